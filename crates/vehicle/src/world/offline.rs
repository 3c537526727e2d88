//! The offline stepping loop: a world stepped from t = 0 to the end of a run, stopping at each
//! row instant (and, when asked, at each frame boundary in between) to let a front end look at
//! it. `flexdyn simulate` (one spacecraft: a world of one, [`World::of_one`]) and `flexdyn fleet`
//! (a fleet file) both run through [`walk`]; what a row holds and how it is written (CSV) is the
//! front end's, in the binary.
//!
//! The loop formats nothing and allocates nothing: it only counts steps and calls the sink.

use super::step::World;

/// When the rows fall and where the loop stops between them, in RK4 steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RowPlan {
    /// Steps of the whole run (every vehicle's).
    pub total_steps: u64,
    /// Steps between two rows (≥ 1). A row falls at step 0 and at every multiple of this up to
    /// `total_steps`; the steps after the last row, up to `total_steps`, are stepped without one.
    pub log_steps: u64,
    /// Whether to stop at every frame boundary between the rows too ([`RowSink::frame`]): a
    /// sensor sampled at frame boundaries (a star tracker) samples where a server would.
    pub frame_stops: bool,
    /// The step the world is at when the walk begins: 0 for a run from t = 0, or a resumed
    /// checkpoint's. A resumed walk stops only after it: its rows are the multiples of
    /// `log_steps` beyond it, its frame stops the boundaries beyond it (what fell on it was
    /// written before the checkpoint).
    pub start_step: u64,
}

impl RowPlan {
    /// Rows the plan writes: one at step 0 and one per whole log interval (from a resumed
    /// start, those beyond it).
    pub fn rows(&self) -> u64 {
        (self.total_steps / self.log_steps.max(1) + 1).saturating_sub(self.first_row())
    }

    /// The index of the first row the walk writes.
    fn first_row(&self) -> u64 {
        if self.start_step == 0 {
            0
        } else {
            self.start_step / self.log_steps.max(1) + 1
        }
    }
}

/// What a front end does at the loop's stops.
pub trait RowSink {
    /// The error a row can end the run with (an output error, a non-finite state).
    type Error;

    /// At step 0 and at every frame boundary reached between rows, when the plan asks for
    /// frame stops; before [`Self::row`] when both fall on the same step. Nothing by default.
    fn frame(&mut self, _world: &mut World, _step: u64) {}

    /// Row `k`, at step `step` (= `k · log_steps`).
    fn row(&mut self, world: &mut World, k: u64, step: u64) -> Result<(), Self::Error>;
}

/// Steps `world` through `plan`, calling `sink` at each stop; the rows written. An error from
/// the sink stops the run there. The environment models run on the stepping thread: a batch run
/// offloading them to a worker ran slower whenever the other core was busy (a campaign's other
/// runs, a build), since the worker's looks take the CPU the stepping thread needs
/// (`benches/acs_full.rs`, columns `vehicle` and `1 thread`).
pub fn walk<S: RowSink>(world: &mut World, plan: RowPlan, sink: &mut S) -> Result<u64, S::Error> {
    let log_steps = plan.log_steps.max(1);
    let steps_per_frame = world.steps_per_frame().max(1);
    let n_logged = plan.total_steps / log_steps;
    let mut step = plan.start_step;
    if plan.frame_stops && step == 0 {
        sink.frame(world, 0);
    }
    for k in plan.first_row()..=n_logged {
        // Step to the row, stopping at each frame boundary when the plan asks for it.
        let row_step = k * log_steps;
        while step < row_step {
            let next = if plan.frame_stops {
                row_step.min((step / steps_per_frame + 1) * steps_per_frame)
            } else {
                row_step
            };
            world.step_n(next - step);
            step = next;
            if plan.frame_stops && step.is_multiple_of(steps_per_frame) {
                sink.frame(world, step);
            }
        }
        sink.row(world, k, step)?;
    }
    // Steps after the last multiple of the log interval, up to the duration.
    world.step_n(plan.total_steps.saturating_sub(step));
    Ok(plan.rows())
}

#[cfg(test)]
mod tests {
    use super::{walk, RowPlan, RowSink, World};
    use crate::config::{SimConfig, DEFAULT_CONFIG_TOML};
    use crate::sim::Simulation;

    /// Records where the loop stopped.
    #[derive(Default)]
    struct Stops {
        frames: Vec<u64>,
        rows: Vec<(u64, u64, u64)>,
    }

    impl RowSink for Stops {
        type Error = ();
        fn frame(&mut self, world: &mut World, step: u64) {
            assert_eq!(
                world.t_sim_ns(),
                step * 1_000_000,
                "frame stop at step {step}"
            );
            self.frames.push(step);
        }
        fn row(&mut self, world: &mut World, k: u64, step: u64) -> Result<(), ()> {
            self.rows.push((k, step, world.t_sim_ns()));
            if k == 99 {
                return Err(());
            }
            Ok(())
        }
    }

    /// The reference spacecraft: a 1 ms step, 10 steps per frame (100 Hz).
    fn world() -> World {
        let cfg = SimConfig::from_toml_str(DEFAULT_CONFIG_TOML).unwrap();
        World::of_one("sc".into(), 1, Simulation::new(&cfg).unwrap())
    }

    #[test]
    fn rows_fall_on_whole_intervals_and_the_tail_is_stepped_without_one() {
        // 25 steps, a row every 7: rows at 0, 7, 14, 21; the last 4 steps without a row.
        let mut w = world();
        let mut s = Stops::default();
        let plan = RowPlan {
            total_steps: 25,
            log_steps: 7,
            frame_stops: false,
            start_step: 0,
        };
        assert_eq!(walk(&mut w, plan, &mut s), Ok(4));
        assert_eq!(plan.rows(), 4);
        let at: Vec<(u64, u64)> = s.rows.iter().map(|r| (r.0, r.1)).collect();
        assert_eq!(at, [(0, 0), (1, 7), (2, 14), (3, 21)]);
        // Each row sees the world at its own step (1 ms each).
        assert!(s.rows.iter().all(|r| r.2 == r.1 * 1_000_000));
        assert!(s.frames.is_empty());
        assert_eq!(w.t_sim_ns(), 25_000_000);
    }

    #[test]
    fn frame_stops_fall_on_every_frame_boundary_between_rows() {
        // Rows every 7 steps, frames every 10: frame stops at 0, 10, 20, none in the tail
        // (21 to 25).
        let mut w = world();
        let mut s = Stops::default();
        let plan = RowPlan {
            total_steps: 25,
            log_steps: 7,
            frame_stops: true,
            start_step: 0,
        };
        assert_eq!(walk(&mut w, plan, &mut s), Ok(4));
        assert_eq!(s.frames, [0, 10, 20]);
        assert_eq!(s.rows.len(), 4);
        assert_eq!(w.t_sim_ns(), 25_000_000);
    }

    #[test]
    fn a_resumed_walk_stops_only_after_its_start() {
        // Resumed at step 14 (a row and not a frame boundary): rows at 21 only (14 was written
        // before the checkpoint), frame stops at 20 only; then the tail to 25.
        let mut w = world();
        w.step_n(14);
        let mut s = Stops::default();
        let plan = RowPlan {
            total_steps: 25,
            log_steps: 7,
            frame_stops: true,
            start_step: 14,
        };
        assert_eq!(plan.rows(), 1);
        assert_eq!(walk(&mut w, plan, &mut s), Ok(1));
        assert_eq!(s.frames, [20]);
        let at: Vec<(u64, u64)> = s.rows.iter().map(|r| (r.0, r.1)).collect();
        assert_eq!(at, [(3, 21)]);
        assert_eq!(w.t_sim_ns(), 25_000_000);
    }

    #[test]
    fn a_row_error_stops_the_run_there() {
        let mut w = world();
        let mut s = Stops::default();
        let plan = RowPlan {
            total_steps: 1000,
            log_steps: 1,
            frame_stops: false,
            start_step: 0,
        };
        assert_eq!(walk(&mut w, plan, &mut s), Err(()));
        assert_eq!(s.rows.len(), 100);
        assert_eq!(w.t_sim_ns(), 99_000_000);
    }
}
