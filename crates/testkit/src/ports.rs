//! Free loopback ports without a race: every process a test starts listens on port 0, the OS
//! gives it a free port, and the process reports the port it got; the test reads the report.
//! Nothing picks a number and hopes it is still free when the process binds it (a port read from
//! a released `127.0.0.1:0` socket can be taken meanwhile, e.g. as the ephemeral source port of
//! some other connection).
//!
//! - In-process Zenoh sessions read their port back with `flexdyn_proto::client::transport::listening_on`.
//! - `flexdyn run` and `flexdyn replay` log `Zenoh listening on tcp/127.0.0.1:PORT`
//!   ([`zenoh_endpoint`]); `flexdyn view` logs `… on ws://127.0.0.1:PORT` ([`ws_port`]). Both are
//!   `info` lines on stderr, so [`reporting`] pipes stderr and sets `RUST_LOG=info`.
//! - A test that needs an endpoint where nobody listens holds one ([`closed_endpoint`]).

use std::io::{BufRead, BufReader};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The endpoint to listen on: loopback, any free port.
pub const ANY_PORT: &str = "tcp/127.0.0.1:0";

/// How long a process may take to report where it listens.
const REPORT_TIMEOUT: Duration = Duration::from_secs(60);

/// `cmd` set up so its listen report can be read: stderr piped, `RUST_LOG=info`.
pub fn reporting(cmd: &mut Command) -> &mut Command {
    cmd.env("RUST_LOG", "info").stderr(Stdio::piped())
}

/// Reads `child`'s stderr (piped, see [`reporting`]) until a line holds `marker` and returns
/// what follows it up to the next space or comma. The rest of stderr keeps being read (and
/// echoed to the test's stderr) on a thread, so the child never blocks on a full pipe.
pub fn reported(child: &mut Child, marker: &str) -> String {
    let stderr = child
        .stderr
        .take()
        .expect("the child's stderr must be piped (see `reporting`)");
    let (tx, rx) = mpsc::channel::<String>();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines() {
            let Ok(line) = line else { break };
            eprintln!("[child] {line}");
            let _ = tx.send(line);
        }
    });
    let give_up = Instant::now() + REPORT_TIMEOUT;
    loop {
        let left = give_up.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(line) => {
                if let Some(value) = value_after(&line, marker) {
                    return format!("{marker}{value}");
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                panic!("the child reported no `{marker}` within {REPORT_TIMEOUT:?}")
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                let status = child.wait().ok();
                panic!("the child ended ({status:?}) without reporting `{marker}`")
            }
        }
    }
}

/// What follows `marker` in `line`, up to the next space or comma.
fn value_after(line: &str, marker: &str) -> Option<String> {
    let (_, rest) = line.split_once(marker)?;
    Some(
        rest.chars()
            .take_while(|c| !c.is_whitespace() && *c != ',')
            .collect(),
    )
}

/// The endpoint a `Zenoh listening on …` line reports in `stderr` text collected so far (only
/// complete lines count, so a port is never read half-written).
pub fn find_zenoh_endpoint(stderr: &str) -> Option<String> {
    let complete = &stderr[..stderr.rfind('\n')?];
    complete
        .lines()
        .find_map(|line| value_after(line, "Zenoh listening on "))
}

/// The Zenoh endpoint `flexdyn run` / `flexdyn replay` reports: `tcp/127.0.0.1:PORT`.
pub fn zenoh_endpoint(child: &mut Child) -> String {
    let line = reported(child, "Zenoh listening on ");
    line["Zenoh listening on ".len()..].to_owned()
}

/// The WebSocket port `flexdyn view` reports.
pub fn ws_port(child: &mut Child) -> u16 {
    let line = reported(child, "ws://127.0.0.1:");
    line["ws://127.0.0.1:".len()..]
        .parse()
        .expect("a port number after ws://127.0.0.1:")
}

/// A loopback endpoint where nobody listens, held so that nobody can start listening there
/// while the returned guard lives: the local port of a connected client socket. A connection
/// to it is refused (no listener), and no other socket can bind the port while the client
/// socket holds it. For the tests of a tool that finds no server.
pub fn closed_endpoint() -> (String, ClosedPort) {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind 127.0.0.1:0");
    let client = TcpStream::connect(listener.local_addr().unwrap()).expect("connect to it");
    let (server_side, _) = listener.accept().expect("accept");
    let port = client.local_addr().unwrap().port();
    (
        format!("tcp/127.0.0.1:{port}"),
        ClosedPort(client, server_side),
    )
}

/// Keeps the port of [`closed_endpoint`] taken: the two ends are held, never read.
pub struct ClosedPort(#[allow(dead_code)] TcpStream, #[allow(dead_code)] TcpStream);

/// The port of `tcp/127.0.0.1:PORT`.
pub fn port_of(endpoint: &str) -> u16 {
    endpoint
        .rsplit_once(':')
        .and_then(|(_, p)| p.parse().ok())
        .unwrap_or_else(|| panic!("no port in {endpoint:?}"))
}
