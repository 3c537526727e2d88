//! Both names of the Foxglove WebSocket protocol on one port.
//!
//! The protocol specified as `foxglove.websocket.v1` is negotiated by the Foxglove SDK under its
//! newer name `foxglove.sdk.v1` only; the messages are the same (Foxglove's stated position),
//! but clients that offer only the old name (older Foxglove Studio and Lichtblick builds,
//! roslibjs-foxglove, hand-written clients) get HTTP 400 from the SDK. `flexdyn view` therefore
//! accepts connections itself, renames `foxglove.websocket.v1` to `foxglove.sdk.v1` in the
//! upgrade request (and back in the response), and then relays the bytes unchanged to the SDK
//! server listening on an ephemeral loopback port. Clients offering the new name pass through
//! untouched. The `Sec-WebSocket-Accept` digest covers the key only, so the rename is invisible
//! to the WebSocket handshake.
//!
//! A request without `Upgrade: websocket` (a browser opening `http://HOST:PORT/`) gets the web
//! page of [`crate::web`] instead, from this same port: a Foxglove-WebSocket client that connects back
//! here (issue 36).

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

use crate::web;

/// The protocol's original name.
pub const LEGACY: &str = "foxglove.websocket.v1";
/// The name the SDK negotiates.
pub const CURRENT: &str = "foxglove.sdk.v1";
/// Longest HTTP head accepted.
const MAX_HEAD: usize = 16 * 1024;

/// Reads until the end of an HTTP head; returns (head, bytes after it).
async fn read_head(s: &mut TcpStream) -> std::io::Result<(String, Vec<u8>)> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 2048];
    loop {
        if let Some(end) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            let rest = buf.split_off(end + 4);
            return Ok((String::from_utf8_lossy(&buf).into_owned(), rest));
        }
        if buf.len() > MAX_HEAD {
            return Err(std::io::Error::other("HTTP head too long"));
        }
        let n = s.read(&mut chunk).await?;
        if n == 0 {
            return Err(std::io::Error::other("closed during the HTTP head"));
        }
        buf.extend_from_slice(&chunk[..n]);
    }
}

/// Rewrites the value of every `Sec-WebSocket-Protocol` header line of `head` with `f`.
fn rewrite_protocol(head: &str, f: impl Fn(&str) -> String) -> String {
    head.split("\r\n")
        .map(|line| match line.split_once(':') {
            Some((name, value)) if name.trim().eq_ignore_ascii_case("sec-websocket-protocol") => {
                format!("{name}: {}", f(value.trim()))
            }
            _ => line.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\r\n")
}

/// The request head with the old name renamed, and whether the client offered only it.
pub fn client_head(head: &str) -> (String, bool) {
    let mut offers_current = false;
    let mut offers_legacy = false;
    for line in head.split("\r\n") {
        if let Some((name, value)) = line.split_once(':') {
            if name.trim().eq_ignore_ascii_case("sec-websocket-protocol") {
                for p in value.split(',') {
                    offers_current |= p.trim() == CURRENT;
                    offers_legacy |= p.trim() == LEGACY;
                }
            }
        }
    }
    if offers_current || !offers_legacy {
        return (head.to_owned(), false);
    }
    let renamed = rewrite_protocol(head, |v| {
        v.split(',')
            .map(|p| {
                if p.trim() == LEGACY {
                    CURRENT
                } else {
                    p.trim()
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    });
    (renamed, true)
}

/// The response head with the SDK's name turned back into the old one.
pub fn server_head(head: &str) -> String {
    rewrite_protocol(head, |v| {
        if v == CURRENT {
            LEGACY.to_owned()
        } else {
            v.to_owned()
        }
    })
}

async fn relay(mut client: TcpStream, upstream: std::net::SocketAddr) -> std::io::Result<()> {
    let (head, rest) = read_head(&mut client).await?;
    if !web::is_upgrade(&head) {
        if let Some(wait) = web::hold(&head) {
            tokio::time::sleep(wait).await;
        }
        client.write_all(&web::respond(&head)).await?;
        client.shutdown().await?;
        return Ok(());
    }
    let (head, legacy) = client_head(&head);
    let mut server = TcpStream::connect(upstream).await?;
    server.set_nodelay(true)?;
    client.set_nodelay(true)?;
    server.write_all(head.as_bytes()).await?;
    server.write_all(&rest).await?;
    let (resp, rest) = read_head(&mut server).await?;
    let resp = if legacy { server_head(&resp) } else { resp };
    client.write_all(resp.as_bytes()).await?;
    client.write_all(&rest).await?;
    tokio::io::copy_bidirectional(&mut client, &mut server).await?;
    Ok(())
}

/// Accepts on `listener` forever, relaying each connection to `upstream`.
pub async fn serve(listener: TcpListener, upstream: std::net::SocketAddr) {
    loop {
        match listener.accept().await {
            Ok((client, peer)) => {
                tokio::spawn(async move {
                    if let Err(e) = relay(client, upstream).await {
                        tracing::debug!(%peer, error = %e, "viewer connection ended");
                    }
                });
            }
            Err(e) => {
                tracing::warn!(error = %e, "cannot accept a viewer connection");
                tokio::time::sleep(std::time::Duration::from_millis(100)).await;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_client_offering_just_the_old_name_is_renamed() {
        let req =
            "GET / HTTP/1.1\r\nHost: x\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n";
        let (head, legacy) = client_head(req);
        assert!(legacy);
        assert!(
            head.contains("Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n"),
            "{head}"
        );
        let both = "GET / HTTP/1.1\r\nsec-websocket-protocol: foxglove.websocket.v1, foxglove.sdk.v1\r\n\r\n";
        assert_eq!(client_head(both), (both.to_owned(), false));
        let resp =
            "HTTP/1.1 101 Switching Protocols\r\nsec-websocket-protocol: foxglove.sdk.v1\r\n\r\n";
        assert!(server_head(resp).contains("sec-websocket-protocol: foxglove.websocket.v1\r\n"));
    }
}
