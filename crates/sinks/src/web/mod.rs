//! The web page `flexdyn view` serves on its port to a plain HTTP GET (issue 36): a
//! Foxglove-WebSocket client in plain JavaScript that connects back to the same port and draws
//! the spacecraft, plots and the run state on canvases. Its files are compiled into the binary
//! (`assets/web/`), so it needs no network, no CDN and nothing installed but a browser.
//!
//! A request that asks for a WebSocket upgrade (`Upgrade: websocket`) is not answered here: it
//! goes on to the Foxglove server as before (`super::relay`).

/// The page.
const INDEX_HTML: &str = include_str!("../../assets/web/index.html");
/// Its script: the protocol client, the 3D view and the plots.
const APP_JS: &str = include_str!("../../assets/web/app.js");

/// Whether an HTTP request head asks for a WebSocket upgrade (an `Upgrade` header naming
/// `websocket`, case-insensitively).
pub fn is_upgrade(head: &str) -> bool {
    head.split("\r\n").skip(1).any(|line| {
        line.split_once(':').is_some_and(|(name, value)| {
            name.trim().eq_ignore_ascii_case("upgrade")
                && value
                    .split(',')
                    .any(|v| v.trim().eq_ignore_ascii_case("websocket"))
        })
    })
}

/// Longest wait `/hold` grants.
pub const MAX_HOLD: std::time::Duration = std::time::Duration::from_secs(30);

/// The request's path and query (`/app.js`, `ms=4000`) and its method.
fn target(head: &str) -> (&str, &str, &str) {
    let request_line = head.split("\r\n").next().unwrap_or_default();
    let mut parts = request_line.split_ascii_whitespace();
    let method = parts.next().unwrap_or_default();
    let target = parts.next().unwrap_or_default();
    let target = target.split('#').next().unwrap_or_default();
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    (method, path, query)
}

/// How long to wait before answering `GET /hold?ms=N` (at most [`MAX_HOLD`]), `None` for every
/// other request. The page asks for it with `?hold=N`: the image it loads from there keeps the
/// page's load event pending for N ms of real time, so that a headless browser
/// (`--virtual-time-budget`, `--dump-dom`, `--screenshot`), whose virtual clock waits for
/// pending fetches but not for WebSocket data, captures the page with N ms of the stream in it.
pub fn hold(head: &str) -> Option<std::time::Duration> {
    let (method, path, query) = target(head);
    if method != "GET" || path != "/hold" {
        return None;
    }
    let ms = query
        .split('&')
        .find_map(|kv| kv.strip_prefix("ms="))
        .and_then(|v| v.parse::<u64>().ok())
        .unwrap_or(0);
    Some(std::time::Duration::from_millis(ms).min(MAX_HOLD))
}

/// The full HTTP/1.1 response (head and body) to a request head that is not an upgrade. The
/// connection closes after it (`Connection: close`).
pub fn respond(head: &str) -> Vec<u8> {
    let (method, path, _) = target(head);
    let (status, content_type, body): (&str, &str, &[u8]) = match (method, path) {
        ("GET" | "HEAD", "/" | "/index.html") => {
            ("200 OK", "text/html; charset=utf-8", INDEX_HTML.as_bytes())
        }
        ("GET" | "HEAD", "/app.js") => (
            "200 OK",
            "text/javascript; charset=utf-8",
            APP_JS.as_bytes(),
        ),
        ("GET" | "HEAD", "/favicon.ico" | "/hold") => ("204 No Content", "text/plain", b""),
        ("GET" | "HEAD", _) => (
            "404 Not Found",
            "text/plain; charset=utf-8",
            b"not found: flexdyn view serves its page at /\n",
        ),
        _ => (
            "405 Method Not Allowed",
            "text/plain; charset=utf-8",
            b"flexdyn view answers GET (the page) and WebSocket upgrades (Foxglove)\n",
        ),
    };
    let mut out = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n",
        body.len()
    );
    if status.starts_with("405") {
        out.push_str("Allow: GET, HEAD\r\n");
    }
    out.push_str("\r\n");
    let mut bytes = out.into_bytes();
    if method != "HEAD" && !status.starts_with("204") {
        bytes.extend_from_slice(body);
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_websocket_upgrade_is_told_apart_from_a_page_request() {
        assert!(is_upgrade(
            "GET / HTTP/1.1\r\nHost: x\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n\r\n"
        ));
        assert!(is_upgrade("GET / HTTP/1.1\r\nupgrade: WebSocket\r\n\r\n"));
        assert!(!is_upgrade(
            "GET / HTTP/1.1\r\nHost: x\r\nAccept: text/html\r\n\r\n"
        ));
    }

    #[test]
    fn the_page_and_its_script_are_served_and_other_paths_are_not() {
        let page = String::from_utf8(respond("GET / HTTP/1.1\r\nHost: x\r\n\r\n")).unwrap();
        assert!(page.starts_with("HTTP/1.1 200 OK\r\n"), "{page}");
        assert!(page.contains("Content-Type: text/html"));
        assert!(page.contains("<script src=\"app.js\">"));
        let len: usize = page
            .split("\r\n")
            .find_map(|l| l.strip_prefix("Content-Length: "))
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(len, INDEX_HTML.len());
        assert!(page.ends_with(INDEX_HTML));
        let js = String::from_utf8(respond("GET /app.js?v=1 HTTP/1.1\r\n\r\n")).unwrap();
        assert!(js.contains("foxglove.websocket.v1"));
        let head = String::from_utf8(respond("HEAD / HTTP/1.1\r\n\r\n")).unwrap();
        assert!(head.ends_with("\r\n\r\n"), "HEAD has no body: {head}");
        assert!(String::from_utf8(respond("GET /x HTTP/1.1\r\n\r\n"))
            .unwrap()
            .starts_with("HTTP/1.1 404"));
        assert_eq!(
            hold("GET /hold?ms=1500 HTTP/1.1\r\n\r\n"),
            Some(std::time::Duration::from_millis(1500))
        );
        assert_eq!(
            hold("GET /hold?ms=99999999 HTTP/1.1\r\n\r\n"),
            Some(MAX_HOLD)
        );
        assert_eq!(hold("GET /?hold=5 HTTP/1.1\r\n\r\n"), None);
        assert!(
            String::from_utf8(respond("GET /hold?ms=1 HTTP/1.1\r\n\r\n"))
                .unwrap()
                .starts_with("HTTP/1.1 204")
        );
        assert!(String::from_utf8(respond("POST / HTTP/1.1\r\n\r\n"))
            .unwrap()
            .starts_with("HTTP/1.1 405"));
    }
}
