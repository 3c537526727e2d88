//! flexdyn-wiregen: every mirror of the wire protocol, written from one table,
//! `proto/schema/messages.toml` ([`table`]).
//!
//! [`mirrors`] returns each generated file's path and text; the binary writes them
//! (`cargo run -p flexdyn-wiregen`) and the tests fail when a file in the tree differs
//! (`cargo test -p flexdyn-wiregen`), so a mirror cannot lag behind the table.
//!
//! | mirror | module |
//! |---|---|
//! | the byte tables of `proto/README.md` (between markers) | [`readme`] |
//! | the header-only C codec, `proto/c/include/flexdyn_proto.h` | [`c_proto`] |
//! | the Python package's codec, `clients/python/src/flexdyn/proto.py` | [`py_proto`] |
//! | the Rust codec's per-message code (sizes, constants, length rules, checks, decoders), `proto/src/wire.rs` | [`rust_wire`] |
//! | the Rust message types (structs, enums, unions, codes and bits, `Default`s, docs), `proto/src/messages.rs` | [`rust_types`] |
//! | the Rust in-place views (every message read without allocating), `proto/src/views.rs` | [`rust_views`] |
//! | the C client library's typed calls, `clients/c/include/flexdyn_client_messages.h` | [`c_client`] |
//! | the C client library's message kinds, `clients/c/src/kinds.rs` | [`c_client`] |
//! | the C client library's `#[repr(C)]` mirrors of the header's structs and the conversions from the Rust messages, `clients/c/src/ctypes.rs` | [`c_ctypes`] |
//! | the JSON Schemas of the messages' JSON (MCAP decoded channels, Foxglove), `proto/schema/json/*.json` and `proto/src/json_schemas.rs` | [`json_schema`] |

pub mod c_client;
pub mod c_ctypes;
pub mod c_members;
pub mod c_proto;
pub mod json_schema;
pub mod py_proto;
pub mod readme;
pub mod rust_types;
pub mod rust_views;
pub mod rust_wire;
pub mod sizes;
pub mod table;

use std::path::{Path, PathBuf};

pub use table::{Table, TableError, TABLE_PATH};

/// The README whose byte tables are generated.
pub const README_PATH: &str = "proto/README.md";
/// The C client library's generated header.
pub const C_HEADER_PATH: &str = "clients/c/include/flexdyn_client_messages.h";
/// The header-only C codec.
pub const C_PROTO_PATH: &str = "proto/c/include/flexdyn_proto.h";
/// The Python package's codec.
pub const PY_PROTO_PATH: &str = "clients/python/src/flexdyn/proto.py";
/// The Rust codec's per-message code.
pub const RUST_WIRE_PATH: &str = "proto/src/wire.rs";
/// The Rust message types.
pub const RUST_TYPES_PATH: &str = "proto/src/messages.rs";
/// The Rust in-place views.
pub const RUST_VIEWS_PATH: &str = "proto/src/views.rs";
/// The C client library's generated kind table.
pub const KINDS_PATH: &str = "clients/c/src/kinds.rs";
/// The C client library's mirrors of the header's structs.
pub const CTYPES_PATH: &str = "clients/c/src/ctypes.rs";
/// The wire crate's generated index of the JSON Schemas.
pub const JSON_SCHEMAS_RS_PATH: &str = "proto/src/json_schemas.rs";
/// The directory of the generated JSON Schemas, one `<Message>.json` each.
pub const JSON_SCHEMA_DIR: &str = "proto/schema/json";

/// A generated file: its path under the repository root and its whole text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mirror {
    /// Path relative to the repository root.
    pub path: PathBuf,
    /// The file's text.
    pub text: String,
}

/// Reads the table under `root` (the repository).
pub fn read_table(root: &Path) -> Result<Table, String> {
    let path = root.join(TABLE_PATH);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    Table::parse(TABLE_PATH, &text).map_err(|e| e.to_string())
}

/// Every mirror of the table under `root`. The README is read to keep its prose.
pub fn mirrors(root: &Path) -> Result<Vec<Mirror>, String> {
    let table = read_table(root)?;
    let readme_path = root.join(README_PATH);
    let readme = std::fs::read_to_string(&readme_path)
        .map_err(|e| format!("{}: {e}", readme_path.display()))?;
    Ok([
        Mirror {
            path: README_PATH.into(),
            text: readme::splice(&table, README_PATH, &readme)?,
        },
        Mirror {
            path: C_HEADER_PATH.into(),
            text: c_client::header(&table),
        },
        Mirror {
            path: C_PROTO_PATH.into(),
            text: c_proto::header(&table),
        },
        Mirror {
            path: PY_PROTO_PATH.into(),
            text: py_proto::module(&table),
        },
        Mirror {
            path: RUST_WIRE_PATH.into(),
            text: rust_wire::module(&table),
        },
        Mirror {
            path: RUST_TYPES_PATH.into(),
            text: rust_types::module(&table, TABLE_PATH).map_err(|e| e.to_string())?,
        },
        Mirror {
            path: RUST_VIEWS_PATH.into(),
            text: rust_views::module(&table)?,
        },
        Mirror {
            path: KINDS_PATH.into(),
            text: c_client::kinds_rs(&table),
        },
        Mirror {
            path: CTYPES_PATH.into(),
            text: c_ctypes::module(&table),
        },
        Mirror {
            path: JSON_SCHEMAS_RS_PATH.into(),
            text: json_schema::rust_module(&table),
        },
    ]
    .into_iter()
    .chain(table.messages.iter().map(|m| Mirror {
        path: Path::new(JSON_SCHEMA_DIR).join(format!("{}.json", m.name)),
        text: json_schema::schema(&table, &m.name).unwrap_or_default(),
    }))
    .collect())
}

/// The mirrors under `root` whose file differs from the table's text.
pub fn stale(root: &Path) -> Result<Vec<PathBuf>, String> {
    Ok(mirrors(root)?
        .into_iter()
        .filter(|m| std::fs::read_to_string(root.join(&m.path)).ok().as_deref() != Some(&m.text))
        .map(|m| m.path)
        .collect())
}
