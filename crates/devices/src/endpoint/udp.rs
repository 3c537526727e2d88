//! A device as a UDP socket pair: the gateway's socket is bound to the local address and
//! connected to the driver's, so it takes datagrams from that address only. Each output frame
//! goes out as one datagram; each datagram that comes in is a chunk of the device's byte stream
//! (a frame split across datagrams is reassembled by the framing, as on a stream).

use std::io::ErrorKind;
use std::net::{SocketAddr, UdpSocket};
use std::os::fd::{AsFd, BorrowedFd};

use super::EndpointError;

/// The gateway's end of a UDP socket pair.
#[derive(Debug)]
pub struct Udp {
    socket: UdpSocket,
    remote: SocketAddr,
    /// Datagrams the driver's side refused (ICMP port unreachable: no driver bound there yet).
    pub unreachable: u64,
}

impl Udp {
    /// Binds `local` (port 0: one the system picks) and connects to `remote`.
    pub fn open(local: SocketAddr, remote: SocketAddr) -> Result<Self, EndpointError> {
        let err = |addr, reason: String| EndpointError::Socket { addr, reason };
        let socket = UdpSocket::bind(local).map_err(|e| err(local, format!("cannot bind: {e}")))?;
        socket
            .connect(remote)
            .map_err(|e| err(remote, format!("cannot connect: {e}")))?;
        socket
            .set_nonblocking(true)
            .map_err(|e| err(local, e.to_string()))?;
        Ok(Self {
            socket,
            remote,
            unreachable: 0,
        })
    }

    /// The bound address, with the port the system picked.
    pub fn local_addr(&self) -> SocketAddr {
        self.socket.local_addr().unwrap_or(self.remote)
    }

    /// The driver's address.
    pub fn remote(&self) -> SocketAddr {
        self.remote
    }

    /// Reads one datagram (non-blocking): 0 when none is there.
    pub fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        loop {
            match self.socket.recv(buf) {
                Ok(n) => return Ok(n),
                Err(e) if e.kind() == ErrorKind::WouldBlock => return Ok(0),
                Err(e) if e.kind() == ErrorKind::ConnectionRefused => {
                    // A previous datagram found no driver: note it, and look again.
                    self.unreachable += 1;
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }

    /// Sends `frame` as one datagram: `Some(true)` sent, `Some(false)` no room yet (try
    /// again), `None` refused (no driver bound there: nobody hears it).
    pub fn send(&mut self, frame: &[u8]) -> std::io::Result<Option<bool>> {
        match self.socket.send(frame) {
            Ok(_) => Ok(Some(true)),
            Err(e) if e.kind() == ErrorKind::WouldBlock => Ok(Some(false)),
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => {
                self.unreachable += 1;
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// The descriptor to wait on.
    pub fn fd(&self) -> BorrowedFd<'_> {
        self.socket.as_fd()
    }
}
