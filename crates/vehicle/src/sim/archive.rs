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
    ///
    /// The schedules' progress is not listed either: a save first applies the schedules at the
    /// checkpoint's instant (as every state record does; a no-op after one), and a restore finds
    /// the rows applied by time in the run's own schedules, so a fork's schedules are the ones in
    /// effect from the checkpoint on. A fork whose scheduled effector inputs in effect then differ
    /// from the checkpoint's hands its own to the effectors at once.
    pub fn archive(&mut self, a: &mut Archive<'_>) {
        if a.is_saving() {
            self.apply_schedules();
        }
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
        let mut fork_inputs = false;
        a.section("vehicle", |a| {
            sc.archive(a);
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
            if !a.is_saving() && !a.failed() {
                // The rows applied by the checkpoint's instant, in this run's schedules.
                let t_ns = sc.t_sim_ns();
                *cursor = schedule.iter().take_while(|r| r.t_start_ns <= t_ns).count();
                *input_cursor = input_schedule
                    .iter()
                    .take_while(|r| r.t_start_ns <= t_ns)
                    .count();
                let mut in_effect = vec![0.0; scheduled_inputs.len()];
                for row in &input_schedule[..*input_cursor] {
                    let r = sc.effector_input_ranges()[row.effector_index].clone();
                    in_effect[r].copy_from_slice(&row.inputs);
                }
                if in_effect != *scheduled_inputs {
                    *scheduled_inputs = in_effect;
                    fork_inputs = true;
                }
            }
        });
        if fork_inputs {
            self.push_inputs();
        }
    }
}
