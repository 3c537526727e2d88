//! [`EndpointSpec`]: where a device's byte stream is exposed, as the device list gives it. The
//! runtime opens it; this crate only reads and checks it.

use std::net::SocketAddr;
use std::path::PathBuf;

/// A device's byte-stream endpoint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EndpointSpec {
    /// A pseudo-terminal; `link` is the symlink to its slave side the driver opens, `baud` the
    /// line rate whose timing the runtime reproduces if given.
    Pty {
        /// Path of the symlink.
        link: PathBuf,
        /// \[bit/s\] line rate.
        baud: Option<u32>,
    },
    /// A TCP server the driver connects to.
    TcpServer {
        /// Address to listen on (port 0: any).
        addr: SocketAddr,
    },
    /// A TCP client connecting to the driver's server.
    TcpClient {
        /// Address to connect to.
        addr: SocketAddr,
    },
    /// A UDP socket pair.
    Udp {
        /// Address the gateway binds.
        local: SocketAddr,
        /// Address the gateway sends to.
        remote: SocketAddr,
    },
}

impl EndpointSpec {
    /// The socket addresses it uses (none for a pty).
    pub fn addresses(&self) -> Vec<SocketAddr> {
        match self {
            EndpointSpec::Pty { .. } => Vec::new(),
            EndpointSpec::TcpServer { addr } | EndpointSpec::TcpClient { addr } => vec![*addr],
            EndpointSpec::Udp { local, remote } => vec![*local, *remote],
        }
    }
}
