//! Plain Zenoh ping-pong, the yardstick of the lockstep benchmark: the same transport, the same
//! sample sizes (a StateMsg out, a CommandMsg back) and the same threading as a lockstep tick,
//! without the simulation.
//!
//! Keys: `flexdyn/<sc>/bench/ping` and `flexdyn/<sc>/bench/pong`.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{bail, Context as _};
use flexdyn_proto::Topics;
use zenoh::handlers::RingChannel;
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

/// `flexdyn/<sc>/bench/ping`
pub fn ping_key(t: &Topics) -> String {
    format!("flexdyn/{}/bench/ping", t.sc_id())
}

/// `flexdyn/<sc>/bench/pong`
pub fn pong_key(t: &Topics) -> String {
    format!("flexdyn/{}/bench/pong", t.sc_id())
}

/// The liveliness token a running pong declares (so ping can wait for it).
pub fn pong_token_key(t: &Topics) -> String {
    format!("flexdyn/{}/bench/pong-ready", t.sc_id())
}

/// Echo server answering from inside the Zenoh subscriber callback (no thread hop; the
/// fastest plain-Zenoh round trip, like Zenoh's `z_pong`). Runs until `stop` returns true.
pub fn pong_in_callback(
    session: &Session,
    topics: &Topics,
    reply_size: usize,
    stop: impl Fn() -> bool,
) -> anyhow::Result<()> {
    let publisher = session
        .declare_publisher(pong_key(topics))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(|e| anyhow::anyhow!("declare pong publisher: {e}"))?;
    let reply = vec![0u8; reply_size];
    let _sub = session
        .declare_subscriber(ping_key(topics))
        .callback(move |_sample| {
            let _ = publisher.put(reply.as_slice()).wait();
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("declare ping subscriber: {e}"))?;
    let _token = session
        .liveliness()
        .declare_token(pong_token_key(topics))
        .wait()
        .map_err(|e| anyhow::anyhow!("declare pong token: {e}"))?;
    while !stop() {
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok(())
}

/// Echo server: answers every ping with `reply_size` bytes from a receive loop on the calling
/// thread (the demo controller's structure). Runs until `stop` returns true (checked every
/// 100 ms) or an error.
pub fn pong(
    session: &Session,
    topics: &Topics,
    reply_size: usize,
    stop: impl Fn() -> bool,
) -> anyhow::Result<()> {
    let sub = session
        .declare_subscriber(ping_key(topics))
        .with(RingChannel::new(8))
        .wait()
        .map_err(|e| anyhow::anyhow!("declare ping subscriber: {e}"))?;
    let publisher = session
        .declare_publisher(pong_key(topics))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(|e| anyhow::anyhow!("declare pong publisher: {e}"))?;
    let _token = session
        .liveliness()
        .declare_token(pong_token_key(topics))
        .wait()
        .map_err(|e| anyhow::anyhow!("declare pong token: {e}"))?;
    let reply = vec![0u8; reply_size];
    while !stop() {
        let Some(_sample) = sub
            .recv_timeout(Duration::from_millis(100))
            .map_err(|e| anyhow::anyhow!("receive ping: {e}"))?
        else {
            continue;
        };
        publisher
            .put(reply.as_slice())
            .wait()
            .map_err(|e| anyhow::anyhow!("publish pong: {e}"))?;
    }
    Ok(())
}

/// Round-trip times of `count` pings of `size` bytes after `warmup` unmeasured ones. Waits up
/// to `timeout` for a pong to be present and for each reply.
pub fn ping(
    session: &Session,
    topics: &Topics,
    size: usize,
    warmup: usize,
    count: usize,
    timeout: Duration,
) -> anyhow::Result<Vec<Duration>> {
    let (tx, rx) = mpsc::sync_channel::<()>(16);
    let _sub = session
        .declare_subscriber(pong_key(topics))
        .callback(move |_sample| {
            let _ = tx.try_send(());
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("declare pong subscriber: {e}"))?;
    let publisher = session
        .declare_publisher(ping_key(topics))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(|e| anyhow::anyhow!("declare ping publisher: {e}"))?;
    // Wait for the pong's token and for its subscriber to match our publisher.
    let give_up = Instant::now() + timeout;
    let tokens = session
        .liveliness()
        .declare_subscriber(pong_token_key(topics))
        .history(true)
        .with(RingChannel::new(4))
        .wait()
        .map_err(|e| anyhow::anyhow!("declare pong token subscriber: {e}"))?;
    let remaining = || give_up.saturating_duration_since(Instant::now());
    if tokens
        .recv_timeout(remaining())
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .is_none()
    {
        bail!("no pong present within {timeout:?}");
    }
    while !publisher
        .matching_status()
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .matching()
    {
        if remaining().is_zero() {
            bail!("the pong's subscriber did not match within {timeout:?}");
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let payload = vec![0u8; size];
    let mut rtts = Vec::with_capacity(count);
    for i in 0..warmup + count {
        let t = Instant::now();
        publisher
            .put(payload.as_slice())
            .wait()
            .map_err(|e| anyhow::anyhow!("publish ping: {e}"))?;
        rx.recv_timeout(timeout)
            .with_context(|| format!("no pong for ping {i} within {timeout:?}"))?;
        if i >= warmup {
            rtts.push(t.elapsed());
        }
    }
    Ok(rtts)
}

/// Round-trip times of `count` StateMsg-sized pings (after `warmup` unmeasured ones) from a
/// session listening on a loopback port the OS chose to a `flexdyn-pingpong pong` child
/// (`pong_exe`; reply CommandMsg-sized), which answers inside its Zenoh callback or, with
/// `recv_loop`, from a receive loop (the demo controller's structure). The benchmarks'
/// yardstick. The child is killed when the pings are done, whatever happened.
pub fn round_trips(
    pong_exe: &std::path::Path,
    warmup: usize,
    count: usize,
    recv_loop: bool,
) -> anyhow::Result<Vec<Duration>> {
    use flexdyn_proto::client::transport::{listening_on, zenoh_config, Role, ZenohArgs};
    use flexdyn_proto::{EFFECTOR_STATE_FIXED_LEN, STATE_FIXED_LEN};
    use std::process::{Command, Stdio};

    /// Kills the pong child on every way out.
    struct Killed(std::process::Child);
    impl Drop for Killed {
        fn drop(&mut self) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }

    let topics = Topics::new("bench").context("bench topics")?;
    let args = ZenohArgs {
        listen: vec!["tcp/127.0.0.1:0".into()],
        ..ZenohArgs::default()
    };
    let session = zenoh::open(zenoh_config(&args, Role::Server)?)
        .wait()
        .map_err(|e| anyhow::anyhow!("open the ping session: {e}"))?;
    let endpoint = listening_on(&session)
        .into_iter()
        .next()
        .context("the ping session listens nowhere")?;
    let mut cmd = Command::new(pong_exe);
    cmd.args(["--connect", &endpoint, "--sc-id", "bench"])
        .args(["pong", "--duration-s", "300"]);
    if recv_loop {
        cmd.arg("--recv-loop");
    }
    let _pong = Killed(
        cmd.stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .with_context(|| format!("spawn {}", pong_exe.display()))?,
    );
    ping(
        &session,
        &topics,
        STATE_FIXED_LEN + 2 * (EFFECTOR_STATE_FIXED_LEN + 32),
        warmup,
        count,
        Duration::from_secs(30),
    )
}
