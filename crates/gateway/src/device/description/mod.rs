//! Device descriptions and the device list: reading them, checking them and building the
//! [`Device`]s they describe.
//!
//! - [`schema`]: the TOML shapes (`serde`);
//! - [`list`]: the device list's endpoints and the loopback rule;
//! - [`build`]: a description resolved against the [`Catalog`];
//! - [`error`]: [`DescriptionError`], naming file, key path and problem.

pub mod build;
pub mod error;
pub mod list;
pub mod schema;

use std::io;
use std::path::{Path, PathBuf};

pub use error::DescriptionError;

use crate::device::catalog::Catalog;
use crate::device::engine::Device;
use build::Context;
use schema::ListFile;

/// Every device of a device list, built.
#[derive(Debug)]
pub struct DeviceSet {
    /// The devices, in list order.
    pub devices: Vec<Device>,
    /// The list allowed non-loopback addresses.
    pub allow_lab_interfaces: bool,
}

impl DeviceSet {
    /// Reads the device list at `list_path` and every description it names (paths relative
    /// to the list file), and builds the devices against `catalog`.
    pub fn load(list_path: &Path, catalog: &Catalog) -> Result<DeviceSet, DescriptionError> {
        let text = std::fs::read_to_string(list_path).map_err(|e| DescriptionError::Read {
            file: list_path.to_owned(),
            message: e.to_string(),
        })?;
        Self::from_str(&text, list_path, |p| std::fs::read_to_string(p), catalog)
    }

    /// As [`DeviceSet::load`], from the list's text, reading each description through
    /// `read_description` (for tests).
    pub fn from_str(
        list_text: &str,
        list_path: &Path,
        read_description: impl Fn(&Path) -> io::Result<String>,
        catalog: &Catalog,
    ) -> Result<DeviceSet, DescriptionError> {
        let list: ListFile = toml::from_str(list_text).map_err(|e| DescriptionError::Syntax {
            file: list_path.to_owned(),
            what: "device list",
            message: e.to_string(),
        })?;
        let dir = list_path.parent().unwrap_or(Path::new(""));
        let mut devices: Vec<Device> = Vec::new();
        for (index, entry) in list.device.iter().enumerate() {
            let key = |k: &str| format!("device[{index}].{k}");
            if entry.name.is_empty() {
                return Err(DescriptionError::invalid(list_path, key("name"), "empty"));
            }
            if devices.iter().any(|d| d.name() == entry.name) {
                return Err(DescriptionError::invalid(
                    list_path,
                    key("name"),
                    format!("`{}` is used twice", entry.name),
                ));
            }
            let endpoint = list::endpoint(list_path, index, entry, list.allow_lab_interfaces)?;
            if let Some(other) = devices.iter().find(|d| clash(d.endpoint(), &endpoint)) {
                return Err(DescriptionError::invalid(
                    list_path,
                    key("endpoint"),
                    format!("`{}` uses the same endpoint", other.name()),
                ));
            }
            let description_path: PathBuf = dir.join(&entry.description);
            let text = read_description(&description_path).map_err(|e| DescriptionError::Read {
                file: description_path.clone(),
                message: format!(
                    "{e} (named by {} `{}`)",
                    list_path.display(),
                    key("description")
                ),
            })?;
            let built = build::build(
                &text,
                &Context {
                    file: &description_path,
                    catalog,
                    bind: &entry.bind,
                },
            )?;
            devices.push(Device::new(
                entry.name.clone(),
                endpoint,
                built.latency_ns,
                built.timeout,
                built.message_names,
                built.behaviour,
            ));
        }
        Ok(DeviceSet {
            devices,
            allow_lab_interfaces: list.allow_lab_interfaces,
        })
    }
}

/// Two endpoints that cannot both be opened: the same pty link, or the same fixed local port.
fn clash(a: &crate::device::EndpointSpec, b: &crate::device::EndpointSpec) -> bool {
    use crate::device::EndpointSpec as E;
    match (a, b) {
        (E::Pty { link: x, .. }, E::Pty { link: y, .. }) => x == y,
        (E::TcpServer { addr: x }, E::TcpServer { addr: y })
        | (E::Udp { local: x, .. }, E::Udp { local: y, .. }) => x == y && x.port() != 0,
        _ => false,
    }
}
