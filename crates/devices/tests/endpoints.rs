//! The endpoints as a driver sees them: a pseudo-terminal opened through its link (raw from
//! the start, every byte value passing unchanged both ways, the driver's presence seen, the
//! link removed when the gateway goes and a stranger's file never replaced), a TCP stream
//! (one driver at a time, the second refused and counted, a reconnect accepted) and a UDP pair.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream, UdpSocket};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use flexdyn_devices::endpoint::pty::Pty;
use flexdyn_devices::endpoint::tcp::Tcp;
use flexdyn_devices::endpoint::udp::Udp;
use flexdyn_devices::endpoint::EndpointError;
use rustix::termios::{tcgetattr, LocalModes};

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Reads from the gateway's side until `n` bytes came (bounded).
fn read_n(mut read: impl FnMut(&mut [u8]) -> usize, n: usize) -> Vec<u8> {
    let mut got = Vec::new();
    let give_up = Instant::now() + Duration::from_secs(5);
    let mut buf = [0u8; 512];
    while got.len() < n && Instant::now() < give_up {
        let k = read(&mut buf);
        got.extend_from_slice(&buf[..k]);
        if k == 0 {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    got
}

#[test]
fn a_pty_is_raw_and_carries_every_byte_value_both_ways() {
    let d = dir("pty_raw");
    let link = d.join("dev.tty");
    let mut pty = Pty::open(&link, Some(115_200)).unwrap();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    // No driver yet: the master sees the slave hung up.
    assert!(!pty.driver_present(true));
    let mut driver = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&link)
        .unwrap();
    assert!(pty.driver_present(true));
    // Raw before the driver touched the line: no canonical mode, no echo, the configured speed.
    let t = tcgetattr(&driver).unwrap();
    assert!(!t.local_modes.contains(LocalModes::ICANON));
    assert!(!t.local_modes.contains(LocalModes::ECHO));
    assert_eq!(t.output_speed(), 115_200);
    // Every byte value, including the ones a cooked line would eat or turn (^C, CR, XON, DEL).
    let all: Vec<u8> = (0..=255u8).collect();
    driver.write_all(&all).unwrap();
    let got = read_n(|b| pty.read(b).unwrap(), all.len());
    assert_eq!(got, all, "driver -> gateway");
    let mut written = 0;
    while written < all.len() {
        written += pty.write(&all[written..]).unwrap().unwrap();
    }
    let mut back = vec![0u8; all.len()];
    driver.read_exact(&mut back).unwrap();
    assert_eq!(back, all, "gateway -> driver");
    // The driver goes: the gateway sees it, and reading gives nothing (not an error).
    drop(driver);
    assert!(!pty.driver_present(true));
    assert_eq!(pty.read(&mut [0u8; 8]).unwrap(), 0);
    assert_eq!(
        pty.write(b"lost").unwrap(),
        None,
        "nobody holds the line: nobody hears it"
    );
    drop(pty);
    assert!(
        std::fs::symlink_metadata(&link).is_err(),
        "the link goes with the gateway"
    );
}

#[test]
fn a_stale_link_is_replaced_and_a_strangers_file_is_not() {
    let d = dir("pty_links");
    let link = d.join("old.tty");
    std::os::unix::fs::symlink("/nonexistent/pts/99", &link).unwrap();
    let pty = Pty::open(&link, None).unwrap();
    assert_eq!(
        std::fs::read_link(&link).unwrap().to_string_lossy(),
        pty.slave()
    );
    // A user's link to something else is left alone.
    let theirs = d.join("theirs.tty");
    let target = d.join("their-file");
    std::fs::write(&target, b"x").unwrap();
    std::os::unix::fs::symlink(&target, &theirs).unwrap();
    let e = Pty::open(&theirs, None).unwrap_err().to_string();
    assert!(e.contains("replaces only links to pseudo-terminals"), "{e}");
    assert_eq!(std::fs::read_link(&theirs).unwrap(), target);
    let file = d.join("plain.tty");
    std::fs::write(&file, b"mine").unwrap();
    match Pty::open(&file, None) {
        Err(e @ EndpointError::Link { .. }) => {
            let m = e.to_string();
            assert!(
                m.contains("plain.tty") && m.contains("other than a symbolic link"),
                "{m}"
            );
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"mine");
    let missing = d.join("no/such/dir/x.tty");
    let e = Pty::open(&missing, None).unwrap_err().to_string();
    assert!(e.contains("does not exist"), "{e}");
    // Linux takes any rate (termios2's BOTHER), as a USB serial adapter does.
    let odd = Pty::open(&d.join("b.tty"), Some(12_345)).unwrap();
    let driver = std::fs::File::open(d.join("b.tty")).unwrap();
    assert_eq!(tcgetattr(&driver).unwrap().output_speed(), 12_345);
    drop(odd);
}

#[test]
fn tcp_takes_one_driver_at_a_time_and_takes_it_back_after_a_reconnect() {
    let mut dev = Tcp::listen("127.0.0.1:0".parse().unwrap()).unwrap();
    let addr = dev.local_addr();
    assert_ne!(addr.port(), 0);
    assert!(!dev.driver_present());
    let mut a = TcpStream::connect(addr).unwrap();
    let wait = |dev: &mut Tcp| {
        let give_up = Instant::now() + Duration::from_secs(5);
        while !dev.driver_present() && Instant::now() < give_up {
            std::thread::sleep(Duration::from_millis(1));
        }
    };
    wait(&mut dev);
    assert!(dev.driver_present());
    let b = TcpStream::connect(addr).unwrap();
    let give_up = Instant::now() + Duration::from_secs(5);
    while dev.refused == 0 && Instant::now() < give_up {
        dev.driver_present();
        std::thread::sleep(Duration::from_millis(1));
    }
    assert_eq!(dev.refused, 1);
    drop(b);
    a.write_all(b"\x00\xC0\xFFhello").unwrap();
    assert_eq!(
        read_n(|buf| dev.read(buf).unwrap(), 8),
        b"\x00\xC0\xFFhello"
    );
    assert_eq!(dev.write(b"back").unwrap(), Some(4));
    let mut four = [0u8; 4];
    a.read_exact(&mut four).unwrap();
    assert_eq!(&four, b"back");
    drop(a);
    // The gateway learns of the close when it reads the end of the stream.
    let give_up = Instant::now() + Duration::from_secs(5);
    while dev.disconnects == 0 && Instant::now() < give_up {
        dev.read(&mut [0u8; 8]).unwrap();
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(!dev.driver_present());
    assert_eq!(
        dev.write(b"lost").unwrap(),
        None,
        "no driver: nobody hears it"
    );
    let _c = TcpStream::connect(addr).unwrap();
    wait(&mut dev);
    assert_eq!((dev.connects, dev.disconnects), (2, 1));
}

#[test]
fn a_tcp_client_device_connects_to_a_listening_driver() {
    let driver = TcpListener::bind("127.0.0.1:0").unwrap();
    let mut dev = Tcp::connect(driver.local_addr().unwrap());
    assert!(dev.driver_present());
    let (mut s, _) = driver.accept().unwrap();
    assert_eq!(dev.write(b"frame").unwrap(), Some(5));
    let mut five = [0u8; 5];
    s.read_exact(&mut five).unwrap();
    assert_eq!(&five, b"frame");
}

#[test]
fn udp_sends_each_frame_as_a_datagram_and_takes_only_the_drivers() {
    let driver = UdpSocket::bind("127.0.0.1:0").unwrap();
    let mut dev = Udp::open("127.0.0.1:0".parse().unwrap(), driver.local_addr().unwrap()).unwrap();
    driver.connect(dev.local_addr()).unwrap();
    assert_eq!(dev.send(b"one").unwrap(), Some(true));
    assert_eq!(dev.send(b"two!").unwrap(), Some(true));
    let mut buf = [0u8; 16];
    assert_eq!(driver.recv(&mut buf).unwrap(), 3);
    assert_eq!(driver.recv(&mut buf).unwrap(), 4);
    // A stranger's datagram is not the driver's: the connected socket never delivers it.
    let stranger = UdpSocket::bind("127.0.0.1:0").unwrap();
    stranger.send_to(b"spoof", dev.local_addr()).unwrap();
    driver.send(b"cmd").unwrap();
    assert_eq!(read_n(|b| dev.read(b).unwrap(), 3), b"cmd");
}
