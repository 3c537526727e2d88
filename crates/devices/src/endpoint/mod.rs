//! Where a device meets its driver: a pseudo-terminal ([`pty`]), a TCP stream ([`tcp`]) or a
//! UDP socket pair ([`udp`]), behind one [`Endpoint`] that reads, writes and says whether a
//! driver is there, never blocking. [`outbox`] holds the frames not yet on the line: those a
//! real-time device sends after its latency (and its baud rate's transmission time), and those
//! a full line could not take yet.

pub mod outbox;
pub mod pty;
pub mod tcp;
pub mod udp;

use std::net::SocketAddr;
use std::os::fd::BorrowedFd;
use std::path::{Path, PathBuf};

use flexdyn_gateway::device::EndpointSpec;
use rustix::event::{PollFd, PollFlags, Timespec};
use rustix::io::Errno;

/// A device's endpoint could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum EndpointError {
    /// A pseudo-terminal call failed.
    #[error("pseudo-terminal for {link}: {what} failed: {reason}")]
    Pty {
        /// The link it was for.
        link: PathBuf,
        /// The call.
        what: String,
        /// Why.
        reason: String,
    },
    /// The link to a pseudo-terminal could not be made.
    #[error("cannot link {link} to the pseudo-terminal: {reason}")]
    Link {
        /// The link.
        link: PathBuf,
        /// Why.
        reason: String,
    },
    /// A socket could not be bound or connected.
    #[error("socket {addr}: {reason}")]
    Socket {
        /// The address.
        addr: SocketAddr,
        /// Why.
        reason: String,
    },
}

/// What a wait on one descriptor found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Readiness {
    /// Bytes (or a connection) to take.
    pub readable: bool,
    /// The other side is gone (a pseudo-terminal's slave that no process holds open).
    pub hung_up: bool,
}

/// Waits up to `timeout_ms` (0: just looks) for `fd` to become readable or hang up.
pub fn poll_one(fd: BorrowedFd<'_>, timeout_ms: i32) -> Result<Readiness, Errno> {
    let mut fds = [PollFd::from_borrowed_fd(fd, PollFlags::IN)];
    let timeout = timespec_ms(timeout_ms);
    rustix::event::poll(&mut fds, timeout.as_ref())?;
    let r = fds[0].revents();
    Ok(Readiness {
        readable: r.contains(PollFlags::IN),
        hung_up: r.contains(PollFlags::HUP),
    })
}

/// Waits up to `timeout_ms` for any of `fds` to become readable (or hang up).
pub fn poll_any(fds: &[BorrowedFd<'_>], timeout_ms: i32) -> Result<(), Errno> {
    let mut p: Vec<PollFd<'_>> = fds
        .iter()
        .map(|fd| PollFd::from_borrowed_fd(*fd, PollFlags::IN))
        .collect();
    let timeout = timespec_ms(timeout_ms);
    match rustix::event::poll(&mut p, timeout.as_ref()) {
        Ok(_) | Err(Errno::INTR) => Ok(()),
        Err(e) => Err(e),
    }
}

fn timespec_ms(ms: i32) -> Option<Timespec> {
    (ms >= 0).then(|| Timespec {
        tv_sec: i64::from(ms / 1000),
        tv_nsec: i64::from(ms % 1000) * 1_000_000,
    })
}

/// One device's endpoint.
#[derive(Debug)]
pub enum Endpoint {
    /// A pseudo-terminal the driver opens through a link.
    Pty(pty::Pty),
    /// A TCP stream (either side listening).
    Tcp(tcp::Tcp),
    /// A UDP socket pair.
    Udp(udp::Udp),
}

impl Endpoint {
    /// Opens the endpoint `spec` describes; a relative pseudo-terminal link is taken relative
    /// to `link_dir`.
    pub fn open(spec: &EndpointSpec, link_dir: &Path) -> Result<Self, EndpointError> {
        Ok(match spec {
            EndpointSpec::Pty { link, baud } => {
                let link = if link.is_absolute() {
                    link.clone()
                } else {
                    link_dir.join(link)
                };
                Self::Pty(pty::Pty::open(&link, *baud)?)
            }
            EndpointSpec::TcpServer { addr } => Self::Tcp(tcp::Tcp::listen(*addr)?),
            EndpointSpec::TcpClient { addr } => Self::Tcp(tcp::Tcp::connect(*addr)),
            EndpointSpec::Udp { local, remote } => Self::Udp(udp::Udp::open(*local, *remote)?),
        })
    }

    /// Where a driver finds it: `pty <link> -> /dev/pts/N`, `tcp_server 127.0.0.1:PORT`, …
    /// (with the ports the system picked).
    pub fn describe(&self) -> String {
        match self {
            Self::Pty(p) => format!("pty {} -> {}", p.link().display(), p.slave()),
            Self::Tcp(t) => format!("tcp {}", t.local_addr()),
            Self::Udp(u) => format!("udp {} <-> {}", u.local_addr(), u.remote()),
        }
    }

    /// Whether a driver is there now (a UDP peer always counts as there).
    pub fn driver_present(&mut self, binary: bool) -> bool {
        match self {
            Self::Pty(p) => p.driver_present(binary),
            Self::Tcp(t) => t.driver_present(),
            Self::Udp(_) => true,
        }
    }

    /// Reads what the driver sent (non-blocking): 0 when nothing is there.
    pub fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Self::Pty(p) => p.read(buf).map_err(std::io::Error::from),
            Self::Tcp(t) => t.read(buf),
            Self::Udp(u) => u.read(buf),
        }
    }

    /// Writes as much of one frame's remaining bytes as the line takes now: `None` when no
    /// driver is there to take them. A UDP frame goes whole or not at all.
    pub fn write(&mut self, frame: &[u8]) -> std::io::Result<Option<usize>> {
        match self {
            Self::Pty(p) => p.write(frame).map_err(std::io::Error::from),
            Self::Tcp(t) => t.write(frame),
            Self::Udp(u) => Ok(u
                .send(frame)?
                .map(|sent| if sent { frame.len() } else { 0 })),
        }
    }

    /// The line's own tallies, by name: connections made, lost and refused (TCP), datagrams
    /// refused (UDP).
    pub fn counters(&self) -> Vec<(&'static str, u64)> {
        match self {
            Self::Pty(_) => Vec::new(),
            Self::Tcp(t) => vec![
                ("link_connects", t.connects),
                ("link_disconnects", t.disconnects),
                ("link_refused_connections", t.refused),
            ],
            Self::Udp(u) => vec![("link_refused_datagrams", u.unreachable)],
        }
    }

    /// The descriptor to wait on for the driver's bytes.
    pub fn fd(&self) -> Option<BorrowedFd<'_>> {
        match self {
            Self::Pty(p) => Some(p.fd()),
            Self::Tcp(t) => t.fd(),
            Self::Udp(u) => Some(u.fd()),
        }
    }
}
