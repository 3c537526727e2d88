//! `flexdyn export FILE.mcap --csv DIR`: one CSV per recorded flexdyn topic, named after its key
//! (`flexdyn/sc1/tlm/state` → `DIR/flexdyn_sc1_tlm_state.csv`), in flexdyn's one CSV dialect
//! ([`super::table`], the writer `simulate` uses too). A column a row does not have (an
//! effector input one command sets and another does not) is left empty. A vehicle's state CSV
//! starts with one `# fault=` line per fault activation its fault events record
//! ([`super::fault_spans::event_comments`]), so `flexdyn plot` shades them from the CSV too;
//! a fault already active when the recording began gets the line of the activation the
//! recording missed ([`super::prior_faults`]: its inferred start, before the first row).
//! A flight-code telemetry row (`flexdyn/<sc>/fsw/<name>`) also gets its stream's names and
//! typed values after the wire columns when the recording's configuration declares the stream
//! ([`super::fsw_columns`]).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};

use super::error::SinkError;
use super::fault_spans;
use super::fsw_columns;
use super::prior_faults;
use super::reader::read_recording;
use super::table::{row, CsvTable};
use super::topics::{classify, Decoded, TopicKind};

/// Arguments of `flexdyn export`.
#[derive(Clone, Debug, PartialEq, clap::Args)]
pub struct ExportArgs {
    /// The recording.
    #[arg(value_name = "FILE.mcap")]
    pub file: PathBuf,
    /// Directory for the CSV files (created if missing).
    #[arg(long, value_name = "DIR")]
    pub csv: PathBuf,
}

/// What an export wrote: CSV path → rows.
pub type ExportReport = BTreeMap<PathBuf, u64>;

fn out_err(path: &Path, e: impl std::fmt::Display) -> SinkError {
    SinkError::Output {
        path: path.to_owned(),
        problem: e.to_string(),
    }
}

/// Exports `args.file` into `args.csv`.
pub fn export(args: &ExportArgs) -> Result<ExportReport, SinkError> {
    let rec = read_recording(&args.file)?;
    if let Some(why) = &rec.truncated {
        tracing::warn!(file = %args.file.display(), reason = %why, "the recording ends early (not closed cleanly); exporting what it holds");
    }
    std::fs::create_dir_all(&args.csv).map_err(|e| out_err(&args.csv, e))?;
    // A sample's cells: the wire's, and for flight-code telemetry its declaration's names.
    let decls = fsw_columns::declarations(&rec);
    let cells = |key: &str, d: &Decoded| {
        let mut cells = row(d);
        if let (Decoded::Fsw(m), Some(decl)) = (d, decls.get(key)) {
            cells.extend(fsw_columns::named_cells(decl, m));
        }
        cells
    };
    // Pass 1: each topic's columns, in first-seen order.
    let mut columns: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut seen: HashMap<String, HashSet<String>> = HashMap::new();
    let mut undecodable = 0u64;
    for s in &rec.samples {
        let Some(topic) = classify(&s.key) else {
            continue;
        };
        let Ok(d) = Decoded::decode(topic.kind, &s.payload) else {
            undecodable += 1;
            continue;
        };
        let names = columns.entry(s.key.clone()).or_default();
        let known = seen.entry(s.key.clone()).or_default();
        for (name, _) in cells(&s.key, &d) {
            if known.insert(name.clone()) {
                names.push(name);
            }
        }
    }
    if undecodable > 0 {
        tracing::warn!(
            undecodable,
            "samples that do not decode were left out of the CSV files"
        );
    }
    // Each vehicle's fault events, as `# fault=` lines of its state CSV (`plot` shades them),
    // with the faults already active when the recording began.
    let fault_lines: HashMap<String, Vec<String>> = prior_faults::fault_events(&rec)
        .into_iter()
        .map(|(sc, v)| {
            let lines = fault_spans::event_comments(&v.events, v.first_state_ns);
            (sc, lines)
        })
        .collect();
    // Pass 2: rows, through the one CSV writer.
    let epochs: HashMap<String, String> = rec
        .vehicles()
        .into_iter()
        .filter_map(|v| Some((v.sc_id, v.epoch_utc?)))
        .collect();
    let mut tables = BTreeMap::new();
    let mut report = ExportReport::new();
    for (key, names) in &columns {
        let path = args.csv.join(format!("{}.csv", key.replace('/', "_")));
        let f = std::fs::File::create(&path).map_err(|e| out_err(&path, e))?;
        // What t_s = 0 is, when the vehicle's configuration has an [epoch].
        let mut comments: Vec<String> = classify(key)
            .and_then(|t| epochs.get(t.sc_id))
            .map(|e| vec![format!("epoch_utc={e}")])
            .unwrap_or_default();
        // The state CSV also carries the vehicle's faults.
        if let Some(t) = classify(key).filter(|t| t.kind == TopicKind::State) {
            comments.extend(fault_lines.get(t.sc_id).into_iter().flatten().cloned());
        }
        let table = CsvTable::with_comments(f, &comments, names).map_err(|e| out_err(&path, e))?;
        tables.insert(key.clone(), (path.clone(), table));
        report.insert(path, 0);
    }
    for s in &rec.samples {
        let (Some(topic), Some((path, table))) = (classify(&s.key), tables.get_mut(&s.key)) else {
            continue;
        };
        let Ok(d) = Decoded::decode(topic.kind, &s.payload) else {
            continue;
        };
        table
            .write_row(&cells(&s.key, &d))
            .map_err(|e| out_err(path, e))?;
        if let Some(n) = report.get_mut(path) {
            *n += 1;
        }
    }
    for (_, (path, mut table)) in tables {
        table.flush().map_err(|e| out_err(&path, e))?;
    }
    Ok(report)
}
