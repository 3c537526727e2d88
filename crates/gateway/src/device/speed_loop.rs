//! A wheel drive's speed loop, as a device behaviour: in speed mode the drive commands
//!
//! ```text
//! torque = clamp(gain · (setpoint − measured), −max, +max)       [N m]
//! ```
//!
//! every tick from the measured wheel speed; a torque command (an in-field whose destination
//! is the loop's torque input) puts it back in torque mode, where it commands nothing.

/// The loop's mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriveMode {
    /// The driver commands torque directly.
    Torque,
    /// The loop holds the setpoint speed.
    Speed,
}

/// A proportional speed loop on one wheel.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedLoop {
    /// The measured speed channel \[rad/s\].
    pub measured_channel: usize,
    /// The torque input it drives \[N m\].
    pub torque_input: usize,
    /// \[N m/(rad/s)\] proportional gain.
    pub gain_nm_per_rad_s: f64,
    /// \[N m\] torque limit (> 0).
    pub max_torque_nm: f64,
    /// \[rad/s\] the setpoint.
    pub setpoint_rad_s: f64,
    /// The mode.
    pub mode: DriveMode,
}

impl SpeedLoop {
    /// A loop in torque mode with a zero setpoint.
    pub fn new(
        measured_channel: usize,
        torque_input: usize,
        gain_nm_per_rad_s: f64,
        max_torque_nm: f64,
    ) -> Self {
        Self {
            measured_channel,
            torque_input,
            gain_nm_per_rad_s,
            max_torque_nm,
            setpoint_rad_s: 0.0,
            mode: DriveMode::Torque,
        }
    }

    /// A new setpoint: speed mode.
    pub fn set_speed(&mut self, setpoint_rad_s: f64) {
        self.setpoint_rad_s = setpoint_rad_s;
        self.mode = DriveMode::Speed;
    }

    /// A torque command was written: torque mode.
    pub fn set_torque_mode(&mut self) {
        self.mode = DriveMode::Torque;
    }

    /// In speed mode, writes the loop's torque into `commands`; a measured speed that is not
    /// finite commands zero torque.
    pub fn drive(&self, values: &[f64], commands: &mut [f64]) {
        if self.mode != DriveMode::Speed {
            return;
        }
        let measured = values
            .get(self.measured_channel)
            .copied()
            .unwrap_or(f64::NAN);
        let torque = if measured.is_finite() {
            (self.gain_nm_per_rad_s * (self.setpoint_rad_s - measured))
                .clamp(-self.max_torque_nm, self.max_torque_nm)
        } else {
            0.0
        };
        if let Some(slot) = commands.get_mut(self.torque_input) {
            *slot = torque;
        }
    }
}
