//! [`Catalog`]: what the runtime offers the devices, built once at start from the served
//! vehicle configuration: groups of `f64` channels published together (one sensor's sample)
//! and the actuator inputs a driver may set, each with its SI unit.
//!
//! A channel's full name is `<group>.<field>` (`star_tracker.st1.q_cn[0]`); the runtime keeps
//! `values[channel]` (the latest value of each channel) and `fresh[group]` (that group
//! published at this tick) indexed as here, and `commands[input]` for the inputs.

/// One `f64` channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channel {
    /// Full name, `<group>.<field>`.
    pub name: String,
    /// SI unit (`"rad/s"`, `"T"`, `"1"`).
    pub unit: String,
    /// Index of its group.
    pub group: usize,
}

/// A group of channels published together.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Group {
    /// Name (`star_tracker.st1`).
    pub name: String,
    /// Index of its first channel; its channels are consecutive.
    pub first_channel: usize,
    /// Number of channels.
    pub channel_count: usize,
}

/// An actuator input a driver may set.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Input {
    /// Name (`wheel.rw1.torque_nm`).
    pub name: String,
    /// SI unit (`"N m"`).
    pub unit: String,
}

/// The channels, groups and inputs on offer, and the frame period.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Catalog {
    frame_ns: u64,
    channels: Vec<Channel>,
    groups: Vec<Group>,
    inputs: Vec<Input>,
}

impl Catalog {
    /// An empty catalog for a server whose frame period is `frame_ns` \[ns\].
    pub fn new(frame_ns: u64) -> Self {
        Self {
            frame_ns,
            channels: Vec::new(),
            groups: Vec::new(),
            inputs: Vec::new(),
        }
    }

    /// \[ns\] The frame period: a periodic output's period must be a whole number of frames.
    pub fn frame_ns(&self) -> u64 {
        self.frame_ns
    }

    /// Adds a group of channels `<group>.<field>` with their SI units; returns the group's
    /// index. Channel indices continue from the previous group's.
    pub fn add_group(&mut self, group: &str, fields: &[(&str, &str)]) -> usize {
        let index = self.groups.len();
        let first_channel = self.channels.len();
        self.channels
            .extend(fields.iter().map(|(field, unit)| Channel {
                name: format!("{group}.{field}"),
                unit: (*unit).to_owned(),
                group: index,
            }));
        self.groups.push(Group {
            name: group.to_owned(),
            first_channel,
            channel_count: fields.len(),
        });
        index
    }

    /// Adds an actuator input with its SI unit; returns its index.
    pub fn add_input(&mut self, name: &str, unit: &str) -> usize {
        self.inputs.push(Input {
            name: name.to_owned(),
            unit: unit.to_owned(),
        });
        self.inputs.len() - 1
    }

    /// Channels (the length of the runtime's `values`).
    pub fn channel_count(&self) -> usize {
        self.channels.len()
    }

    /// Groups (the length of the runtime's `fresh`).
    pub fn group_count(&self) -> usize {
        self.groups.len()
    }

    /// Inputs (the length of the runtime's `commands`).
    pub fn input_count(&self) -> usize {
        self.inputs.len()
    }

    /// The index of the channel of this full name.
    pub fn channel_index(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c.name == name)
    }

    /// The index of the group of this name.
    pub fn group_index(&self, name: &str) -> Option<usize> {
        self.groups.iter().position(|g| g.name == name)
    }

    /// The index of the input of this name.
    pub fn input_index(&self, name: &str) -> Option<usize> {
        self.inputs.iter().position(|i| i.name == name)
    }

    /// Every channel, in index order.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// Every group, in index order.
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }

    /// Every input, in index order.
    pub fn inputs(&self) -> &[Input] {
        &self.inputs
    }

    /// The index of channel `<group>.<field>` of group `group`.
    pub fn field_of(&self, group: usize, field: &str) -> Option<usize> {
        let g = self.groups.get(group)?;
        (g.first_channel..g.first_channel + g.channel_count).find(|&c| {
            self.channels[c]
                .name
                .strip_prefix(g.name.as_str())
                .and_then(|rest| rest.strip_prefix('.'))
                == Some(field)
        })
    }

    /// Up to `limit` names that start like `name` (for an error's list of choices): the
    /// names sharing its longest prefix up to a `.`.
    pub fn suggestions<'a>(
        names: impl Iterator<Item = &'a str> + Clone,
        name: &str,
        limit: usize,
    ) -> Vec<String> {
        let mut prefix = name;
        loop {
            let found: Vec<String> = names
                .clone()
                .filter(|n| n.starts_with(prefix))
                .take(limit)
                .map(str::to_owned)
                .collect();
            if !found.is_empty() || prefix.is_empty() {
                return found;
            }
            prefix = match prefix.rfind('.') {
                Some(dot) => &prefix[..dot],
                None => "",
            };
        }
    }
}
