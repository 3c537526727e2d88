//! `flexdyn plot` from the outside: every figure of a recording and of a `simulate` CSV is a
//! valid PNG (decoded with the `png` crate), of the documented size, and not blank; figures
//! the input has no data for are skipped and named; bad input is an error naming the file.

mod ports;

use std::path::{Path, PathBuf};
use std::process::Command;

fn flexdyn(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .output()
        .unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("plots")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.parent().unwrap()).unwrap();
    d
}

/// The colour of every figure's first line (`src/sinks/plot.rs`, `COLORS[0]`).
const FIRST_LINE_RGB: [u8; 3] = [31, 119, 180];

/// Decodes `path` and returns (width, height, fraction of non-white pixels, distinct colours,
/// pixels of the first line's colour).
fn inspect_png(path: &Path) -> (u32, u32, f64, usize, usize) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.line_size / info.width as usize;
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(bpp).collect();
    let non_white = pixels.iter().filter(|p| p[..3] != [255, 255, 255]).count();
    let line = pixels.iter().filter(|p| p[..3] == FIRST_LINE_RGB).count();
    let mut colours: Vec<&[u8]> = pixels.clone();
    colours.sort_unstable();
    colours.dedup();
    (
        info.width,
        info.height,
        non_white as f64 / pixels.len() as f64,
        colours.len(),
        line,
    )
}

fn check_figures(dir: &Path, names: &[&str]) {
    for name in names {
        let path = dir.join(name);
        assert!(path.is_file(), "{name} was not written");
        let (w, h, ink, colours, line) = inspect_png(&path);
        eprintln!(
            "{name}: {w}×{h}, {:.1} % ink, {colours} colours, {line} px of the first line",
            ink * 100.0
        );
        assert_eq!((w, h), (1200, 800), "{name}");
        // Axes, text and at least one coloured line: a blank or axis-only figure fails.
        assert!(ink > 0.01, "{name} is (nearly) blank: {ink}");
        assert!(colours >= 8, "{name} has only {colours} colours");
        // The data itself: the first series is drawn (a 2 px line across the plot width).
        assert!(line >= 500, "{name}: the first line has only {line} pixels");
    }
}

#[test]
fn a_recording_gives_every_figure() {
    let rec = tmp("batch.mcap");
    let status = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["run", "--mode", "batch", "--duration-s", "5"])
        .args(["--listen", ports::ANY_PORT, "--config"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml"))
        .arg("--record")
        .arg(&rec)
        .status()
        .unwrap();
    assert!(status.success());
    let out = tmp("from_mcap");
    let r = flexdyn(&[
        "plot",
        rec.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--sigma-rn",
        "0.1,0.2,-0.1",
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(!err.contains("skipped"), "{err}");
    check_figures(
        &out,
        &[
            "attitude.png",
            "rates.png",
            "panels.png",
            "wrench.png",
            "conservation.png",
            "imu.png",
            "timing.png",
        ],
    );
}

#[test]
fn a_simulate_csv_gives_the_state_figures_and_names_the_rest() {
    let dir = tmp("from_csv");
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("ref.csv");
    let r = flexdyn(&[
        "simulate",
        "--duration-s",
        "10",
        "--log-every-s",
        "0.05",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(r.status.success());
    let r = flexdyn(&["plot", csv.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    check_figures(
        &dir,
        &[
            "attitude.png",
            "rates.png",
            "panels.png",
            "conservation.png",
        ],
    );
    for skipped in ["wrench.png", "imu.png", "timing.png"] {
        assert!(err.contains(&format!("skipped {skipped}")), "{err}");
        assert!(!dir.join(skipped).exists());
    }

    // Not a state CSV: an error that names the file and the problem, exit code 2.
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "a,b\n1,2\n").unwrap();
    let r = flexdyn(&["plot", bad.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.csv") && err.contains("t_s"), "{err}");
}
