//! The outbox: a frame waits for its instant; on a paced line with a baud rate its instant is
//! when its last byte would have crossed an 8N1 UART (10 bits per byte) after the frames
//! before it; a full outbox drops whole frames and counts them; a line with no driver loses
//! them and counts them.

use std::time::{Duration, Instant};

use flexdyn_devices::endpoint::outbox::Outbox;
use flexdyn_devices::endpoint::udp::Udp;
use flexdyn_devices::endpoint::Endpoint;

#[test]
fn a_paced_frame_goes_when_its_bytes_have_crossed_the_line() {
    let mut o = Outbox::new(1024, Some(115_200));
    let t0 = Instant::now();
    // 33 octets at 115200 baud: 330 bits = 2.864583 ms (truncated to the nanosecond).
    o.push(&[0xAA; 33], t0, true);
    assert_eq!(o.next_due(), Some(t0 + Duration::from_nanos(2_864_583)));
    // The next frame queues behind it on the line: 11 more octets, 110 bits = 954.861 µs.
    let mut o2 = Outbox::new(1024, Some(115_200));
    o2.push(&[0xAA; 33], t0, true);
    o2.push(&[0x55; 11], t0, true);
    o2.flush(t0 + Duration::from_millis(10), &mut sink())
        .unwrap();
    assert_eq!(o2.counters().frames_sent, 2);
    // Unpaced (lockstep): at once, whatever the baud rate.
    let mut o3 = Outbox::new(1024, Some(9_600));
    o3.push(&[0xAA; 33], t0, false);
    assert_eq!(o3.next_due(), Some(t0));
}

#[test]
fn a_full_outbox_drops_whole_frames_and_counts_them() {
    let mut o = Outbox::new(100, None);
    let t0 = Instant::now() + Duration::from_secs(3600);
    for _ in 0..4 {
        o.push(&[1u8; 30], t0, true);
    }
    // 3 × 30 fit in 100 octets; the fourth does not.
    assert_eq!(o.counters().frames_dropped_full, 1);
}

/// A UDP endpoint whose peer is a bound socket that never reads (datagrams go nowhere).
fn sink() -> Endpoint {
    let peer = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = peer.local_addr().unwrap();
    std::mem::forget(peer);
    Endpoint::Udp(Udp::open("127.0.0.1:0".parse().unwrap(), addr).unwrap())
}
