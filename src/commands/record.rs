//! `flexdyn record`: every sample of `flexdyn/<sc-id>/**` to an MCAP file.

use std::process::ExitCode;

use super::{exit, summary};
use flexdyn_sinks::record_cmd::{record, RecordArgs};
use flexdyn_sinks::SinkError;

/// Records until stopped; what was recorded on stderr. Exit 3 when the file is written and
/// readable but not the whole stream.
pub fn main(args: &RecordArgs) -> ExitCode {
    match exit(record(args), SinkError::exit_code) {
        Ok(r) => {
            summary(format_args!(
                "recorded {} samples ({} payload bytes, {} undecodable) to {}; dropped {}; {}",
                r.stats.samples,
                r.stats.payload_bytes,
                r.stats.undecodable,
                args.output.display(),
                r.dropped,
                r.completeness()
            ));
            if r.complete() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(3)
            }
        }
        Err(code) => code,
    }
}
