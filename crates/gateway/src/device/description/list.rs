//! The device list file: which devices, from which descriptions, bound to which sensors, on
//! which endpoints. Socket addresses must be loopback unless `allow_lab_interfaces = true`.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};

use super::schema::{EndpointTable, ListDevice};
use super::DescriptionError;
use crate::device::endpoint::EndpointSpec;

/// The endpoint of `[[device]]` number `index`.
pub fn endpoint(
    file: &Path,
    index: usize,
    device: &ListDevice,
    allow_lab_interfaces: bool,
) -> Result<EndpointSpec, DescriptionError> {
    let key = |k: &str| format!("device[{index}].endpoint.{k}");
    let table: &EndpointTable = &device.endpoint;
    let addr = |k: &str, text: &str| -> Result<SocketAddr, DescriptionError> {
        let addr: SocketAddr = text.parse().map_err(|_| {
            DescriptionError::invalid(
                file,
                key(k),
                format!("`{text}` is not a socket address (`127.0.0.1:5000`, `[::1]:5000`)"),
            )
        })?;
        if !allow_lab_interfaces && !addr.ip().is_loopback() {
            return Err(DescriptionError::invalid(
                file,
                key(k),
                format!(
                    "device `{}`: `{addr}` is not a loopback address; set \
                     `allow_lab_interfaces = true` at the top of the device list to use a lab \
                     interface",
                    device.name
                ),
            ));
        }
        Ok(addr)
    };
    let given = [
        table.pty.is_some(),
        table.tcp_server.is_some(),
        table.tcp_client.is_some(),
        table.udp_local.is_some() || table.udp_remote.is_some(),
    ]
    .iter()
    .filter(|&&g| g)
    .count();
    if given != 1 {
        return Err(DescriptionError::invalid(
            file,
            format!("device[{index}].endpoint"),
            "give exactly one of { pty = \"..\", baud = .. }, { tcp_server = \"..\" }, \
             { tcp_client = \"..\" }, { udp_local = \"..\", udp_remote = \"..\" }",
        ));
    }
    if table.baud.is_some() && table.pty.is_none() {
        return Err(DescriptionError::invalid(
            file,
            key("baud"),
            "only with `pty`",
        ));
    }
    if let Some(link) = &table.pty {
        if link.is_empty() {
            return Err(DescriptionError::invalid(file, key("pty"), "empty path"));
        }
        if table.baud == Some(0) {
            return Err(DescriptionError::invalid(
                file,
                key("baud"),
                "0: give a line rate or none",
            ));
        }
        return Ok(EndpointSpec::Pty {
            link: PathBuf::from(link),
            baud: table.baud,
        });
    }
    if let Some(a) = &table.tcp_server {
        return Ok(EndpointSpec::TcpServer {
            addr: addr("tcp_server", a)?,
        });
    }
    if let Some(a) = &table.tcp_client {
        return Ok(EndpointSpec::TcpClient {
            addr: addr("tcp_client", a)?,
        });
    }
    match (&table.udp_local, &table.udp_remote) {
        (Some(l), Some(r)) => Ok(EndpointSpec::Udp {
            local: addr("udp_local", l)?,
            remote: addr("udp_remote", r)?,
        }),
        _ => Err(DescriptionError::invalid(
            file,
            format!("device[{index}].endpoint"),
            "UDP needs both `udp_local` and `udp_remote`",
        )),
    }
}
