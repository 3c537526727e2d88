//! A device as a pseudo-terminal: the gateway holds the master side, the driver opens the slave
//! through a symbolic link the device list names, exactly as it would open `/dev/ttyS1`.
//!
//! - **Raw mode**: the slave starts in raw mode (`cfmakeraw`: no echo, no line editing, no
//!   CR/NL translation, 8 bits), at the configured baud rate if one is given, so a binary
//!   protocol passes unchanged even before the driver configures the line.
//! - **The driver's own settings**: when the driver opens the slave, the gateway reads the
//!   line's settings once and warns if they cannot carry the protocol (canonical mode on a
//!   binary device, a baud rate other than the one configured), as a real UART would garble.
//! - **Presence**: Linux reports `POLLHUP` on the master while no process holds the slave
//!   open; that is how the gateway knows the driver is there (and waits for it in lockstep).
//!   It therefore keeps no slave descriptor of its own.

use std::ffi::CString;
use std::os::fd::{AsFd, BorrowedFd, OwnedFd};
use std::path::{Path, PathBuf};

use rustix::fs::{Mode, OFlags};
use rustix::io::Errno;
use rustix::pty::OpenptFlags;
use rustix::termios::{LocalModes, OptionalActions};

use super::{poll_one, EndpointError, Readiness};

/// The master side of a pseudo-terminal and the link that names its slave.
#[derive(Debug)]
pub struct Pty {
    master: OwnedFd,
    slave_path: CString,
    link: PathBuf,
    baud: Option<u32>,
    /// Whether a driver held the slave open at the last look.
    present: bool,
    /// Whether a driver has opened it before.
    opened_before: bool,
}

impl Pty {
    /// Opens a pseudo-terminal, puts its slave in raw mode (at `baud` if given) and links `link`
    /// to it. An existing symbolic link at `link` is replaced (a stale one from an earlier run);
    /// anything else there is an error.
    pub fn open(link: &Path, baud: Option<u32>) -> Result<Self, EndpointError> {
        let fail = |what: &str, e: Errno| EndpointError::Pty {
            link: link.to_path_buf(),
            what: what.to_owned(),
            reason: e.to_string(),
        };
        let master = rustix::pty::openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY)
            .map_err(|e| fail("posix_openpt", e))?;
        rustix::pty::grantpt(&master).map_err(|e| fail("grantpt", e))?;
        rustix::pty::unlockpt(&master).map_err(|e| fail("unlockpt", e))?;
        let slave_path =
            rustix::pty::ptsname(&master, Vec::new()).map_err(|e| fail("ptsname", e))?;
        rustix::io::ioctl_fionbio(&master, true).map_err(|e| fail("non-blocking master", e))?;
        {
            // Raw mode before any driver opens it; closed again at once (see the module note).
            let slave = rustix::fs::open(
                slave_path.as_c_str(),
                OFlags::RDWR | OFlags::NOCTTY | OFlags::CLOEXEC | OFlags::NONBLOCK,
                Mode::empty(),
            )
            .map_err(|e| fail("open the slave", e))?;
            let mut t = rustix::termios::tcgetattr(&slave).map_err(|e| fail("tcgetattr", e))?;
            t.make_raw();
            if let Some(b) = baud {
                t.set_speed(b).map_err(|e| EndpointError::Pty {
                    link: link.to_path_buf(),
                    what: format!("baud {b}"),
                    reason: format!("{e} (not a speed termios knows)"),
                })?;
            }
            rustix::termios::tcsetattr(&slave, OptionalActions::Now, &t)
                .map_err(|e| fail("tcsetattr", e))?;
        }
        replace_link(link, Path::new(&*slave_path.to_string_lossy()))?;
        Ok(Self {
            master,
            slave_path,
            link: link.to_path_buf(),
            baud,
            present: false,
            opened_before: false,
        })
    }

    /// The link the driver opens.
    pub fn link(&self) -> &Path {
        &self.link
    }

    /// The slave device the link points to (`/dev/pts/N`).
    pub fn slave(&self) -> String {
        self.slave_path.to_string_lossy().into_owned()
    }

    /// Whether a driver holds the slave open now; on the transition to open, a warning for each
    /// line setting that cannot carry the protocol (`binary`: the device's framing is not text
    /// lines, so canonical mode would hold bytes back until a newline).
    pub fn driver_present(&mut self, binary: bool) -> bool {
        let now = !matches!(poll_one(self.master.as_fd(), 0), Ok(r) if r.hung_up);
        if now && !self.present {
            if self.opened_before {
                // A driver reopened the line: what the last one left unread, or wrote and the
                // gateway did not take, is not this one's.
                let _ =
                    rustix::termios::tcflush(&self.master, rustix::termios::QueueSelector::IOFlush);
            }
            self.opened_before = true;
            self.check_line(binary);
        }
        self.present = now;
        now
    }

    fn check_line(&self, binary: bool) {
        let Ok(slave) = rustix::fs::open(
            self.slave_path.as_c_str(),
            OFlags::RDWR | OFlags::NOCTTY | OFlags::CLOEXEC | OFlags::NONBLOCK,
            Mode::empty(),
        ) else {
            return;
        };
        let Ok(t) = rustix::termios::tcgetattr(&slave) else {
            return;
        };
        if binary && t.local_modes.contains(LocalModes::ICANON) {
            tracing::warn!(
                link = %self.link.display(),
                "the driver left the line in canonical mode: binary frames are held until a \
                 newline byte (cfmakeraw, or clear ICANON)"
            );
        }
        if let Some(b) = self.baud {
            let (i, o) = (t.input_speed(), t.output_speed());
            if i != b || o != b {
                tracing::warn!(
                    link = %self.link.display(),
                    configured = b,
                    driver_in = i,
                    driver_out = o,
                    "the driver set another baud rate than the device's: a real UART would \
                     garble every byte"
                );
            }
        }
    }

    /// Reads what the driver wrote (non-blocking): `Ok(0)` when nothing is there or no driver
    /// holds the slave.
    pub fn read(&mut self, buf: &mut [u8]) -> Result<usize, Errno> {
        match rustix::io::read(&self.master, buf) {
            Ok(n) => Ok(n),
            // EIO: no process holds the slave (the driver closed it); EAGAIN: nothing to read.
            Err(Errno::AGAIN | Errno::IO) => Ok(0),
            Err(e) => Err(e),
        }
    }

    /// Writes as much of `bytes` as the line takes now (non-blocking): the number written,
    /// or `None` when no process holds the slave, so nobody hears them (the kernel would
    /// otherwise keep them for whoever opens the line next).
    pub fn write(&mut self, bytes: &[u8]) -> Result<Option<usize>, Errno> {
        if poll_one(self.master.as_fd(), 0)?.hung_up {
            return Ok(None);
        }
        match rustix::io::write(&self.master, bytes) {
            Ok(n) => Ok(Some(n)),
            Err(Errno::AGAIN) => Ok(Some(0)),
            Err(Errno::IO) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// The descriptor to wait on.
    pub fn fd(&self) -> BorrowedFd<'_> {
        self.master.as_fd()
    }

    /// Readable now, or hung up, within `timeout_ms`.
    pub fn poll(&self, timeout_ms: i32) -> Result<Readiness, Errno> {
        poll_one(self.master.as_fd(), timeout_ms)
    }
}

impl Drop for Pty {
    fn drop(&mut self) {
        // Only our own link: leave anything that replaced it alone.
        if std::fs::read_link(&self.link).is_ok_and(|t| t.as_os_str() == self.slave().as_str()) {
            let _ = std::fs::remove_file(&self.link);
        }
    }
}

/// Points `link` at `target`. A symbolic link already there is replaced only if it is a
/// pseudo-terminal's (`/dev/pts/…`) or dangling: a stale link of an earlier run, never a link a
/// user made to something else. The new link is made under a temporary name and renamed into
/// place, so a driver never sees the path missing or half made.
fn replace_link(link: &Path, target: &Path) -> Result<(), EndpointError> {
    let err = |reason: String| EndpointError::Link {
        link: link.to_path_buf(),
        reason,
    };
    match std::fs::symlink_metadata(link) {
        Ok(m) if m.file_type().is_symlink() => {
            let to = std::fs::read_link(link).map_err(|e| err(e.to_string()))?;
            if !to.starts_with("/dev/pts") && link.exists() {
                return Err(err(format!(
                    "a symbolic link to {} is there; the gateway replaces only links to \
                     pseudo-terminals and dangling ones",
                    to.display()
                )));
            }
        }
        Ok(_) => {
            return Err(err(
                "something other than a symbolic link is there; the gateway replaces only its own links"
                    .into(),
            ))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(err(e.to_string())),
    }
    if let Some(dir) = link.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(err(format!(
                "its directory {} does not exist",
                dir.display()
            )));
        }
    }
    let mut temp = link.as_os_str().to_owned();
    temp.push(format!(".flexdyn-{}", std::process::id()));
    let temp = std::path::PathBuf::from(temp);
    let _ = std::fs::remove_file(&temp);
    std::os::unix::fs::symlink(target, &temp).map_err(|e| err(e.to_string()))?;
    std::fs::rename(&temp, link).map_err(|e| {
        let _ = std::fs::remove_file(&temp);
        err(e.to_string())
    })
}
