//! A vehicle's mutable state for a checkpoint ([`flexdyn_kernel::archive`]).

use flexdyn_dynamics::Wrench;
use flexdyn_kernel::archive::Archive;

use super::Simulation;

impl Simulation {
    /// Lists every mutable part of the vehicle, in order: the spacecraft (state, time, held
    /// inputs, effectors), the schedules' cursors, the commanded wrench and inputs, the sensors,
    /// the environment and the faults. What it was built from (the configuration, the
    /// schedules themselves) is not listed: restore into a vehicle built from a compatible
    /// configuration. The hub outputs cached for the current frame are dropped on a restore and
    /// recomputed from the restored state (the same bits). Not on the stepping path.
    pub fn archive(&mut self, a: &mut Archive<'_>) {
        // Named field by field: a new field does not compile until it is listed here or marked
        // as configuration (`_`).
        let Simulation {
            sc,
            frame_ns: _,
            schedule,
            cursor,
            command,
            inputs,
            input_schedule,
            input_cursor,
            scheduled_inputs,
            applied_inputs,
            outputs_scratch,
            flags_scratch,
            frame_outputs,
            sensors,
            environment,
            epoch: _,
            environment_every_frames: _,
            faults,
        } = self;
        a.section("vehicle", |a| {
            sc.archive(a);
            let mut n = *cursor;
            a.length("wrench schedule rows applied", &mut n, schedule.len());
            *cursor = n;
            let Wrench {
                force_b_newton,
                torque_b_nm,
            } = command;
            a.put(force_b_newton);
            a.put(torque_b_nm);
            for v in [
                &mut *inputs,
                &mut *scheduled_inputs,
                &mut *applied_inputs,
                &mut *outputs_scratch,
            ] {
                a.expect_count("effector values", v.len());
                a.put(&mut v[..]);
            }
            a.expect_count("effector flags", flags_scratch.len());
            a.put(&mut flags_scratch[..]);
            let mut n = *input_cursor;
            a.length("input schedule rows applied", &mut n, input_schedule.len());
            *input_cursor = n;
            if !a.is_saving() {
                *frame_outputs = None;
            }
            sensors.archive(a);
            let mut has_environment = environment.is_some();
            a.put(&mut has_environment);
            match (has_environment, environment.as_mut()) {
                (true, Some(env)) => env.archive(a),
                (false, None) => {}
                (found, _) => a.invalid(
                    "an environment (1) where this run has none, or none (0)",
                    found.into(),
                ),
            }
            faults.archive(a);
        });
    }
}
