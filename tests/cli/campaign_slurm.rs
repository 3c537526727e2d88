//! `flexdyn campaign submit --slurm` and `resubmit` on a real single-node Slurm cluster that the
//! test starts on this machine: Debian's `slurm-wlm` and `munge` (installed through
//! `tests/deps/debian_package.sh` when missing, as root), a `slurm.conf` for one node on
//! loopback ports the OS hands out, `munged`, `slurmctld` and `slurmd`.
//!
//! A campaign of 20 lockstep runs under the demo controller is run twice: by `campaign run`
//! here, and submitted to Slurm as a job array. Two of the array's tasks are cancelled before
//! they start (an infrastructure failure, as a lost node or a time limit is): the summarize
//! job reports them as could-not-run with their Slurm state, and the verdict is INCOMPLETE
//! (exit 1). `campaign resubmit --wait` then submits exactly those two, and the campaign
//! passes (exit 0) with every run's state hash equal to the local run's.
//!
//! Where the daemons cannot run (not root and Slurm not installed, no apt-get, a cluster that
//! never comes up), the test says so loudly on stderr and passes without checking: nothing
//! here can be checked without a cluster.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use flexdyn_testkit::demo_bin::acs_demo;

/// The single-node cluster: its files and daemons, stopped on drop.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<Child>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for d in &mut self.daemons {
            let _ = d.kill();
            let _ = d.wait();
        }
        if let Ok(pid) = std::fs::read_to_string(self.dir.join("munged.pid")) {
            let _ = Command::new("kill").arg(pid.trim()).status();
        }
    }
}

/// Says loudly why the cluster could not be had, and returns `None`.
fn skip(why: &str) -> Option<Cluster> {
    eprintln!(
        "\n*** SKIPPED campaign_slurm: {why}\n*** `campaign submit --slurm` was NOT checked on this machine.\n"
    );
    None
}

/// `program` present (installing Debian's `package` as root if it is not).
fn installed(program: &str, package: &str) -> bool {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/deps/debian_package.sh");
    Command::new("sh")
        .arg(script)
        .args([program, package])
        .status()
        .is_ok_and(|s| s.success())
}

/// A free loopback TCP port from the OS.
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

fn output(program: &str, args: &[&str], conf: &Path) -> Option<Output> {
    Command::new(program)
        .args(args)
        .env("SLURM_CONF", conf)
        .output()
        .ok()
}

/// Starts munged, slurmctld and slurmd on this machine; `None` (after saying why) where that
/// cannot be done.
fn start_cluster() -> Option<Cluster> {
    for (program, package) in [
        ("munged", "munge"),
        ("slurmctld", "slurm-wlm"),
        ("slurmd", "slurm-wlm"),
    ] {
        if !installed(program, package) {
            return skip(&format!(
                "{program} (Debian package {package}) is not installed and could not be"
            ));
        }
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("slurm-cluster");
    let _ = std::fs::remove_dir_all(&dir);
    for d in ["state", "spool", "munge"] {
        std::fs::create_dir_all(dir.join(d)).unwrap();
    }
    // munged wants a private key and a private directory.
    let key = dir.join("munge/munge.key");
    std::fs::write(
        &key,
        (0..1024u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(dir.join("munge"), std::fs::Permissions::from_mode(0o700)).unwrap();
    std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o400)).unwrap();
    let socket = dir.join("munge/munge.socket");
    let munged = Command::new("munged")
        .arg("--force")
        .arg(format!("--socket={}", socket.display()))
        .arg(format!("--key-file={}", key.display()))
        .arg(format!("--pid-file={}", dir.join("munged.pid").display()))
        .arg(format!("--log-file={}", dir.join("munged.log").display()))
        .arg(format!("--seed-file={}", dir.join("munge/seed").display()))
        .status();
    if !munged.as_ref().is_ok_and(|s| s.success()) {
        return skip(&format!(
            "munged did not start ({munged:?}); its log: {}",
            dir.join("munged.log").display()
        ));
    }
    let host = String::from_utf8_lossy(&Command::new("hostname").arg("-s").output().ok()?.stdout)
        .trim()
        .to_owned();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let conf = dir.join("slurm.conf");
    let d = dir.display();
    std::fs::write(
        &conf,
        format!(
            "ClusterName=flexdyntest\n\
             SlurmctldHost={host}(127.0.0.1)\n\
             SlurmctldPort={}\n\
             SlurmdPort={}\n\
             SlurmUser=root\n\
             SlurmdUser=root\n\
             AuthType=auth/munge\n\
             AuthInfo=socket={}\n\
             CredType=cred/munge\n\
             StateSaveLocation={d}/state\n\
             SlurmdSpoolDir={d}/spool\n\
             SlurmctldPidFile={d}/slurmctld.pid\n\
             SlurmdPidFile={d}/slurmd.pid\n\
             SlurmctldLogFile={d}/slurmctld.log\n\
             SlurmdLogFile={d}/slurmd.log\n\
             ProctrackType=proctrack/linuxproc\n\
             TaskPlugin=task/none\n\
             JobAcctGatherType=jobacct_gather/none\n\
             AccountingStorageType=accounting_storage/none\n\
             SchedulerType=sched/backfill\n\
             SelectType=select/cons_tres\n\
             SelectTypeParameters=CR_Core\n\
             MinJobAge=3600\n\
             ReturnToService=2\n\
             MpiDefault=none\n\
             NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\n\
             PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP\n",
            free_port(),
            free_port(),
            socket.display()
        ),
    )
    .unwrap();
    let mut cluster = Cluster {
        dir: dir.clone(),
        conf: conf.clone(),
        daemons: Vec::new(),
    };
    for daemon in ["slurmctld", "slurmd"] {
        match Command::new(daemon)
            .args(["-D", "-f"])
            .arg(&conf)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
        {
            Ok(c) => cluster.daemons.push(c),
            Err(e) => return skip(&format!("{daemon} could not be started: {e}")),
        }
    }
    // The node is up once sinfo says it is idle.
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(60) {
        if let Some(o) = output("sinfo", &["--noheader", "--format=%T"], &conf) {
            if String::from_utf8_lossy(&o.stdout).trim() == "idle" {
                return Some(cluster);
            }
        }
        std::thread::sleep(Duration::from_millis(250));
    }
    skip(&format!(
        "the one-node cluster never came up (logs: {d}/slurmctld.log, {d}/slurmd.log)"
    ))
}

/// `flexdyn ARGS` with the cluster's configuration: exit code and report (stderr).
fn flexdyn(args: &[&str], conf: &Path) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .env("SLURM_CONF", conf)
        .env("RUST_LOG", "warn")
        .output()
        .expect("runs the flexdyn binary");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Every run's state hash in campaign directory `out`, by run.
fn hashes(out: &Path, runs: u32) -> Vec<String> {
    (0..runs)
        .map(|i| {
            let path = out.join(format!("run-{i:04}/result.json"));
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let r: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!(r["outcome"], "passed", "{}: {text}", path.display());
            r["state_sha256"].as_str().unwrap().to_owned()
        })
        .collect()
}

#[test]
fn a_campaign_submitted_to_slurm_matches_the_local_run_and_resubmits_what_could_not_run() {
    let Some(cluster) = start_cluster() else {
        return;
    };
    let conf = cluster.conf.clone();
    let dir = cluster.dir.join("campaign");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("campaign.toml");
    const RUNS: u32 = 20;
    std::fs::write(
        &file,
        format!(
            r#"runs = {RUNS}
seed = 29
duration_s = 3.0
sigma_rn = [0.1, 0.2, -0.1]
participant_timeout_s = 10.0
controller = '''{} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} --sigma-rn 0.1,0.2,-0.1 --rate-source truth --log-every-s 0 --idle-exit-s 1'''

[resources]
cpus_per_run = 1

[[dispersions]]
key = "hub.inertia_bc_b_kg_m2[0][0]"
distribution = "normal"
sigma = 45.0

[[dispersions]]
key = "initial.omega_bn_b_rad_s"
distribution = "normal"
sigma = 0.01

[[criteria]]
name = "rate_bounded"
quantity = "omega"
statistic = "max"
below = 1.0
"#,
            acs_demo()
        ),
    )
    .unwrap();
    let f = file.to_str().unwrap();

    let local = dir.join("local");
    let (code, report) = flexdyn(
        &[
            "campaign",
            "run",
            f,
            "--output",
            local.to_str().unwrap(),
            "--jobs",
            "2",
            "--base-port",
            "0",
        ],
        &conf,
    );
    assert_eq!(code, Some(0), "{report}");
    let expected = hashes(&local, RUNS);

    // Submitted without waiting; tasks 18 and 19 are cancelled while they wait their turn.
    let on_slurm = dir.join("slurm");
    let o = on_slurm.to_str().unwrap();
    let (code, report) = flexdyn(&["campaign", "submit", f, "--output", o, "--slurm"], &conf);
    assert_eq!(code, Some(0), "{report}");
    let words: Vec<&str> = report.split_whitespace().collect();
    let after = |w: &str| {
        words
            .iter()
            .position(|x| *x == w)
            .map(|i| words[i + 2].to_owned())
    };
    let array = after("array").expect("the array job's id");
    let summarize = after("summarize").expect("the summarize job's id");
    assert!(
        report.contains(&format!("submitted {RUNS} runs as Slurm array job {array}")),
        "{report}"
    );
    for task in [18, 19] {
        let s = output("scancel", &[&format!("{array}_{task}")], &conf).expect("scancel runs");
        assert!(s.status.success(), "{s:?}");
    }
    let started = Instant::now();
    loop {
        let q = output(
            "squeue",
            &["--noheader", "--jobs", &summarize, "--format=%i"],
            &conf,
        )
        .expect("squeue runs");
        if String::from_utf8_lossy(&q.stdout).trim().is_empty() {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(600),
            "the summarize job never ended"
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    // The summarize job's verdict: two runs could not run, named with their Slurm state.
    let summary = std::fs::read_to_string(on_slurm.join("summary.txt")).unwrap();
    for task in [18, 19] {
        let result =
            std::fs::read_to_string(on_slurm.join(format!("run-{task:04}/result.json"))).unwrap();
        // Cancelled before they started: on a cluster without accounting (this one), Slurm
        // keeps no record of them.
        let why = format!(
            "Slurm task {array}_{task} has no record (cancelled before it started?) and left \
             no result"
        );
        assert!(result.contains(&why), "{result}");
        assert!(
            summary.contains(&format!("run {task} could not be run: {why}")),
            "{summary}"
        );
    }
    let (code, report) = flexdyn(&["campaign", "summarize", o], &conf);
    assert_eq!(code, Some(1), "{report}");
    assert!(
        report.contains("verdict: INCOMPLETE: 2 of 20 runs could not be run"),
        "{report}"
    );

    // Resubmitted: exactly the two, and the campaign passes with the local run's hashes.
    let (code, report) = flexdyn(&["campaign", "resubmit", o, "--wait"], &conf);
    assert_eq!(code, Some(0), "{report}");
    assert!(
        report.contains("submitted 2 runs as Slurm array job"),
        "{report}"
    );
    assert!(
        report.contains("verdict: PASSED: all 20 runs passed"),
        "{report}"
    );
    let script = std::fs::read_to_string(on_slurm.join("slurm/submissions.json")).unwrap();
    let subs: serde_json::Value = serde_json::from_str(&script).unwrap();
    assert_eq!(subs[1]["indices"], serde_json::json!([18, 19]), "{script}");
    assert_eq!(hashes(&on_slurm, RUNS), expected);
}
