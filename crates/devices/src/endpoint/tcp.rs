//! A device as a TCP byte stream: the gateway listens and the driver connects (`tcp_server`),
//! or the gateway connects to a driver that listens (`tcp_client`). One driver at a time: a
//! second connection to a listening device is closed at once and counted, as a serial line has
//! one end. Either side may go away and come back; bytes written while no driver is connected
//! are lost, as on a line with nothing plugged in.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::os::fd::{AsFd, BorrowedFd};
use std::time::{Duration, Instant};

use super::EndpointError;

/// How long a connect attempt of a `tcp_client` device may take, and how often it retries.
const CONNECT_TIMEOUT: Duration = Duration::from_millis(100);
const CONNECT_RETRY: Duration = Duration::from_millis(200);

/// One end of a TCP byte stream.
#[derive(Debug)]
pub struct Tcp {
    listener: Option<TcpListener>,
    peer: SocketAddr,
    stream: Option<TcpStream>,
    last_attempt: Option<Instant>,
    /// Connections closed because one was already active.
    pub refused: u64,
    /// Connections made, and lost.
    pub connects: u64,
    /// Connections lost.
    pub disconnects: u64,
}

impl Tcp {
    /// Listens on `addr` (port 0: one the system picks; [`Tcp::local_addr`] says which).
    pub fn listen(addr: SocketAddr) -> Result<Self, EndpointError> {
        let listener = TcpListener::bind(addr).map_err(|e| EndpointError::Socket {
            addr,
            reason: format!("cannot listen: {e}"),
        })?;
        listener
            .set_nonblocking(true)
            .map_err(|e| EndpointError::Socket {
                addr,
                reason: e.to_string(),
            })?;
        Ok(Self {
            listener: Some(listener),
            peer: addr,
            stream: None,
            last_attempt: None,
            refused: 0,
            connects: 0,
            disconnects: 0,
        })
    }

    /// Connects to a driver listening on `addr` (at once and whenever the connection is lost).
    pub fn connect(addr: SocketAddr) -> Self {
        Self {
            listener: None,
            peer: addr,
            stream: None,
            last_attempt: None,
            refused: 0,
            connects: 0,
            disconnects: 0,
        }
    }

    /// Where a listening device listens (with the port the system picked), or the address a
    /// connecting one connects to.
    pub fn local_addr(&self) -> SocketAddr {
        self.listener
            .as_ref()
            .and_then(|l| l.local_addr().ok())
            .unwrap_or(self.peer)
    }

    /// Whether a driver is connected now (accepting or connecting first if none is).
    pub fn driver_present(&mut self) -> bool {
        match &self.listener {
            Some(l) => loop {
                match l.accept() {
                    Ok((s, from)) => {
                        if self.stream.is_some() {
                            self.refused += 1;
                            tracing::warn!(%from, "a second driver connected: closed (one driver per device)");
                            drop(s);
                        } else if s.set_nonblocking(true).is_ok() {
                            let _ = s.set_nodelay(true);
                            self.connects += 1;
                            tracing::info!(%from, "driver connected");
                            self.stream = Some(s);
                        }
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                    Err(e) => {
                        tracing::warn!("accept: {e}");
                        break;
                    }
                }
            },
            None if self.stream.is_none()
                && self
                    .last_attempt
                    .is_none_or(|t| t.elapsed() >= CONNECT_RETRY) =>
            {
                self.last_attempt = Some(Instant::now());
                if let Ok(s) = TcpStream::connect_timeout(&self.peer, CONNECT_TIMEOUT) {
                    if s.set_nonblocking(true).is_ok() {
                        let _ = s.set_nodelay(true);
                        self.connects += 1;
                        tracing::info!(peer = %self.peer, "connected to the driver");
                        self.stream = Some(s);
                    }
                }
            }
            None => {}
        }
        self.stream.is_some()
    }

    fn lost(&mut self) {
        self.stream = None;
        self.disconnects += 1;
        tracing::info!(peer = %self.peer, "driver connection closed");
    }

    /// Reads what the driver sent (non-blocking): 0 when nothing is there.
    pub fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let Some(s) = &mut self.stream else {
            return Ok(0);
        };
        match s.read(buf) {
            Ok(0) => {
                self.lost();
                Ok(0)
            }
            Ok(n) => Ok(n),
            Err(e) if e.kind() == ErrorKind::WouldBlock || e.kind() == ErrorKind::Interrupted => {
                Ok(0)
            }
            Err(e) if is_gone(&e) => {
                self.lost();
                Ok(0)
            }
            Err(e) => Err(e),
        }
    }

    /// Writes as much of `bytes` as the connection takes now; `None` with no driver connected.
    pub fn write(&mut self, bytes: &[u8]) -> std::io::Result<Option<usize>> {
        let Some(s) = &mut self.stream else {
            return Ok(None);
        };
        match s.write(bytes) {
            Ok(n) => Ok(Some(n)),
            Err(e) if e.kind() == ErrorKind::WouldBlock || e.kind() == ErrorKind::Interrupted => {
                Ok(Some(0))
            }
            Err(e) if is_gone(&e) => {
                self.lost();
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// The descriptor to wait on: the connection, else the listener.
    pub fn fd(&self) -> Option<BorrowedFd<'_>> {
        match (&self.stream, &self.listener) {
            (Some(s), _) => Some(s.as_fd()),
            (None, Some(l)) => Some(l.as_fd()),
            (None, None) => None,
        }
    }
}

fn is_gone(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::ConnectionReset | ErrorKind::BrokenPipe | ErrorKind::ConnectionAborted
    )
}
