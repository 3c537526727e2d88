//! The generated C and Python codecs on the shapes the table's layout rules allow in a message,
//! its union and its vecs, not only on those today's messages happen to use: a bool array, a
//! bounded u8 count, a text field, an i32, finite floats, a union whose variants carry a bool, an
//! enum and a vec of structs that themselves hold a vec, and a vec of primitives at a message's
//! end. (Structs nested whole are today's Header, AppliedWrench and SysTime, covered by the
//! goldens and the fuzzers; the Rust half is compiled only from the real table, so only the real
//! messages exercise it.)
//!
//! Two probe messages are appended to the real table; the generators write the C header and the
//! Python module from it; buffers are packed here by hand, little-endian, at offsets worked out
//! from the field list (not from the generator), and both codecs must decode them to the values
//! packed, re-encode them to the same bytes, and refuse each broken variant with the decoder
//! rules' reason and field.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use flexdyn_wiregen::Table;

const PROBES: &str = r#"
[[enum]]
name = "ProbeMode"
doc = "a probe's mode"
values = [
  { value = 0, name = "Off" },
  { value = 1, name = "Low" },
  { value = 2, name = "High" },
]

[[struct]]
name = "ProbeItem"
doc = "an element with a vec of its own"
fields = [
  { name = "id", type = "u16" },
  { name = "data", type = "vec<u32>", max = 3 },
  { name = "weight", type = "f64", finite = true },
]

[[union]]
name = "ProbePick"
c_prefix = "PROBE_PICK"
doc = "a choice"
variants = [
  { tag = 0, name = "Scalar", doc = "a float and a bool", fields = [
    { name = "x", type = "f64", finite = true },
    { name = "on", type = "bool" },
  ] },
  { tag = 1, name = "Nothing", doc = "nothing", fields = [] },
  { tag = 2, name = "Items", doc = "an enum and elements", fields = [
    { name = "level", type = "enum<ProbeMode>" },
    { name = "items", type = "vec<ProbeItem>", max = 4 },
  ] },
]

[[message]]
name = "ProbeMsg"
c_name = "probe"
title = "probe"
key = "flexdyn/<sc-id>/probe/<name>"
direction = "server"
since = 9
doc = "every fixed shape, then a union"
fields = [
  { name = "header", type = "Header" },
  { name = "flag", type = "bool" },
  { name = "mode", type = "enum<ProbeMode>" },
  { name = "bits", type = "bool[2]" },
  { name = "count", type = "u8", max = 3 },
  { name = "label", type = "u8[8]", text = true, rust_type = "ProbeLabel" },
  { name = "offset", type = "i32" },
  { name = "vals", type = "f64[2]", finite = true },
  { name = "pick", type = "union<ProbePick>" },
]

[[message]]
name = "ProbeListMsg"
c_name = "probe_list"
title = "probe list"
key = "flexdyn/<sc-id>/probe_list"
direction = "server"
since = 9
doc = "a vec of primitives at the end"
fields = [
  { name = "header", type = "Header" },
  { name = "n16", type = "u16" },
  { name = "samples", type = "vec<i32>", max = 5 },
]
"#;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn probe_table() -> Table {
    let text = std::fs::read_to_string(root().join(flexdyn_wiregen::TABLE_PATH)).unwrap();
    Table::parse("messages.toml + probes", &format!("{text}\n{PROBES}")).unwrap()
}

/// A little-endian buffer packed field by field.
#[derive(Default)]
struct Le(Vec<u8>);

impl Le {
    fn u8(mut self, v: u8) -> Self {
        self.0.push(v);
        self
    }
    fn u16(mut self, v: u16) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn u32(mut self, v: u32) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn i32(mut self, v: i32) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn u64(mut self, v: u64) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn f64(mut self, v: f64) -> Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn bytes(mut self, v: &[u8]) -> Self {
        self.0.extend(v);
        self
    }
    /// The header: version 12, spacecraft 7, tick 11, 22 ns, seq 33.
    fn header() -> Self {
        Le::default().u16(12).u32(7).u64(11).u64(22).u64(33)
    }
}

/// A ProbeMsg up to its union tag: flag 1 @30, mode 2 @31, bits [1, 0] @35, count 3 @37, label
/// "ab" @38, offset −5 @46, vals [0.5, −2.25] @50; the tag is at 66.
fn probe_prefix() -> Le {
    Le::header()
        .u8(1)
        .u32(2)
        .u8(1)
        .u8(0)
        .u8(3)
        .bytes(b"ab\0\0\0\0\0\0")
        .i32(-5)
        .f64(0.5)
        .f64(-2.25)
}

/// The cases: a name, the bytes, and what both codecs must print.
fn cases() -> Vec<(&'static str, Vec<u8>, String)> {
    let fixed =
        "hdr 12 7 11 22 33 flag 1 mode 2 bits 1 0 count 3 label ab offset -5 vals 0.5 -2.25";
    let scalar = probe_prefix().u32(0).f64(1.5).u8(1).0;
    let nothing = probe_prefix().u32(1).0;
    // Items: level 1, two elements: (id 4, data [7, 8], weight 0.25), (id 5, data [], weight -1).
    let items = probe_prefix()
        .u32(2)
        .u32(1)
        .u64(2)
        .u16(4)
        .u64(2)
        .u32(7)
        .u32(8)
        .f64(0.25)
        .u16(5)
        .u64(0)
        .f64(-1.0)
        .0;
    let list = Le::header()
        .u16(65535)
        .u64(3)
        .i32(-1)
        .i32(0)
        .i32(2_000_000_000)
        .0;
    let mut out = vec![
        (
            "scalar",
            scalar.clone(),
            format!("OK {fixed} pick 0 x 1.5 on 1"),
        ),
        ("nothing", nothing.clone(), format!("OK {fixed} pick 1")),
        (
            "items",
            items.clone(),
            format!("OK {fixed} pick 2 level 1 items 4 [7 8] 0.25 5 [] -1"),
        ),
        (
            "list",
            list.clone(),
            "OK hdr 12 7 11 22 33 n16 65535 samples -1 0 2000000000".to_string(),
        ),
    ];
    let with = |mut b: Vec<u8>, at: usize, v: &[u8]| {
        b[at..at + v.len()].copy_from_slice(v);
        b
    };
    let nan = f64::NAN.to_le_bytes();
    out.extend([
        (
            "bool 2",
            with(scalar.clone(), 30, &[2]),
            "E Malformed".into(),
        ),
        (
            "enum 3",
            with(scalar.clone(), 31, &[3]),
            "E Malformed".into(),
        ),
        (
            "bits 2",
            with(scalar.clone(), 36, &[2]),
            "E Malformed".into(),
        ),
        (
            "count 4",
            with(scalar.clone(), 37, &[4]),
            "E Malformed".into(),
        ),
        (
            "label padding",
            with(scalar.clone(), 41, b"x"),
            "E Malformed".into(),
        ),
        (
            "vals NaN",
            with(scalar.clone(), 58, &nan),
            "E NonFinite vals[1]".into(),
        ),
        (
            "x NaN",
            with(scalar.clone(), 70, &nan),
            "E NonFinite pick.x".into(),
        ),
        ("on 2", with(scalar.clone(), 78, &[2]), "E Malformed".into()),
        (
            "tag 3",
            with(nothing.clone(), 66, &[3]),
            "E Malformed".into(),
        ),
        (
            "level 3",
            with(items.clone(), 70, &[3]),
            "E Malformed".into(),
        ),
        (
            "weight NaN",
            // The second element's weight: 82 + (2 + 8 + 8 + 8) + 2 + 8 = 118.
            with(items.clone(), 118, &nan),
            "E NonFinite pick.items[].weight".into(),
        ),
        (
            "items 5",
            with(items.clone(), 74, &5u64.to_le_bytes()),
            "E Malformed".into(),
        ),
        (
            "data 4",
            with(items.clone(), 84, &4u64.to_le_bytes()),
            "E Malformed".into(),
        ),
        (
            "short",
            items[..items.len() - 1].to_vec(),
            format!("E Length {} {}", items.len(), items.len() - 1),
        ),
        (
            "long",
            [scalar.clone(), vec![0]].concat(),
            format!("E TrailingBytes {} {}", scalar.len(), scalar.len() + 1),
        ),
        (
            "samples 6",
            with(list.clone(), 32, &6u64.to_le_bytes()),
            "E Malformed".into(),
        ),
    ]);
    out
}

const C_PRINTER: &str = r#"
#include <stdio.h>
#include <stdlib.h>
#include "flexdyn_proto.h"

static void refused(fd_error e) {
    switch (e.status) {
    case FD_ERR_LENGTH: printf("E Length %zu %zu\n", e.needed, e.actual); break;
    case FD_ERR_TRAILING_BYTES: printf("E TrailingBytes %zu %zu\n", e.needed, e.actual); break;
    case FD_ERR_NON_FINITE: printf("E NonFinite %s\n", e.field); break;
    case FD_ERR_MALFORMED: printf("E Malformed\n"); break;
    default: printf("E other %d\n", (int)e.status); break;
    }
}

static void header(const fd_header *h) {
    printf("hdr %u %u %llu %llu %llu", (unsigned)h->protocol_version, (unsigned)h->spacecraft_id,
           (unsigned long long)h->tick, (unsigned long long)h->sim_time_ns,
           (unsigned long long)h->seq);
}

int main(int argc, char **argv) {
    static uint8_t buf[70000], again[70000];
    static fd_probe_item items[8];
    FILE *f = fopen(argv[2], "rb");
    size_t n = fread(buf, 1, sizeof buf, f), i, j;
    (void)argc;
    fclose(f);
    if (strcmp(argv[1], "probe") == 0) {
        fd_probe_msg m;
        fd_error e;
        memset(&m, 0, sizeof m);
        m.items = items;
        m.items_capacity = 8;
        e = fd_decode_probe(buf, n, &m);
        if (e.status != FD_OK) { refused(e); return 0; }
        if (fd_encode_probe(&m, again, sizeof again) != n || memcmp(again, buf, n) != 0) {
            printf("re-encoding differs\n");
            return 1;
        }
        printf("OK ");
        header(&m.header);
        printf(" flag %u mode %u bits %u %u count %u label %s offset %d vals %g %g pick %u",
               (unsigned)m.flag, (unsigned)m.mode, (unsigned)m.bits[0], (unsigned)m.bits[1],
               (unsigned)m.count, (const char *)m.label, (int)m.offset, m.vals[0], m.vals[1],
               (unsigned)m.pick);
        if (m.pick == FD_PROBE_PICK_SCALAR) printf(" x %g on %u", m.x, (unsigned)m.on);
        if (m.pick == FD_PROBE_PICK_ITEMS) {
            printf(" level %u items", (unsigned)m.level);
            for (i = 0; i < m.n_items; ++i) {
                printf(" %u [", (unsigned)m.items[i].id);
                for (j = 0; j < m.items[i].n_data; ++j)
                    printf(j ? " %u" : "%u", (unsigned)m.items[i].data[j]);
                printf("] %g", m.items[i].weight);
            }
        }
        printf("\n");
    } else {
        fd_probe_list_msg m;
        fd_error e = fd_decode_probe_list(buf, n, &m);
        if (e.status != FD_OK) { refused(e); return 0; }
        if (fd_encode_probe_list(&m, again, sizeof again) != n || memcmp(again, buf, n) != 0) {
            printf("re-encoding differs\n");
            return 1;
        }
        printf("OK ");
        header(&m.header);
        printf(" n16 %u samples", (unsigned)m.n16);
        for (i = 0; i < m.n_samples; ++i) printf(" %d", (int)m.samples[i]);
        printf("\n");
    }
    return 0;
}
"#;

const PY_PRINTER: &str = r#"
import sys
sys.path.insert(0, sys.argv[1])
import probe_proto as p

def g(v):
    return ("%g" % v)

for kind, path in zip(sys.argv[2::2], sys.argv[3::2]):
    buf = open(path, "rb").read()
    cls = p.ProbeMsg if kind == "probe" else p.ProbeListMsg
    try:
        m = cls.decode(buf)
    except p.DecodeError as e:
        print(e.canonical() if e.reason != "NonFinite" else "E NonFinite " + e.info["field"])
        continue
    if m.encode() != buf:
        print("re-encoding differs")
        continue
    h = m.header
    s = "OK hdr %d %d %d %d %d" % (h.protocol_version, h.spacecraft_id, h.tick, h.sim_time_ns, h.seq)
    if kind == "probe":
        s += " flag %d mode %d bits %d %d count %d label %s offset %d vals %s %s pick %d" % (
            m.flag, m.mode, m.bits[0], m.bits[1], m.count, m.label_str, m.offset,
            g(m.vals[0]), g(m.vals[1]), m.pick)
        if m.pick == p.PROBE_PICK_SCALAR:
            s += " x %s on %d" % (g(m.x), m.on)
        if m.pick == p.PROBE_PICK_ITEMS:
            s += " level %d items" % m.level
            for it in m.items:
                s += " %d [%s] %s" % (it.id, " ".join(str(d) for d in it.data), g(it.weight))
    else:
        s += " n16 %d samples" % m.n16 + "".join(" %d" % v for v in m.samples)
    print(s)
"#;

#[test]
fn every_allowed_shape_decodes_and_refuses_alike_in_c_and_python() {
    let t = probe_table();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("wire-shapes");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("flexdyn_proto.h"),
        flexdyn_wiregen::c_proto::header(&t),
    )
    .unwrap();
    std::fs::write(
        dir.join("probe_proto.py"),
        flexdyn_wiregen::py_proto::module(&t),
    )
    .unwrap();
    std::fs::write(dir.join("printer.c"), C_PRINTER).unwrap();
    std::fs::write(dir.join("printer.py"), PY_PRINTER).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let exe = dir.join("printer");
    let built = Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-Wconversion",
        ])
        .args(["-Wsign-conversion", "-I"])
        .arg(&dir)
        .arg(dir.join("printer.c"))
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap();
    assert!(
        built.status.success(),
        "{cc}:\n{}",
        String::from_utf8_lossy(&built.stderr)
    );
    let cases = cases();
    let mut py_args = Vec::new();
    let mut want = String::new();
    let mut c_out = String::new();
    for (i, (name, bytes, expected)) in cases.iter().enumerate() {
        let kind = if name.starts_with("list") || name.starts_with("samples") {
            "list"
        } else {
            "probe"
        };
        let file = dir.join(format!("case{i}.bin"));
        std::fs::write(&file, bytes).unwrap();
        let out = Command::new(&exe).arg(kind).arg(&file).output().unwrap();
        assert!(out.status.success(), "C on {name}: {out:?}");
        let got = String::from_utf8_lossy(&out.stdout).trim().to_string();
        assert_eq!(&got, expected, "C on case {name:?}");
        let _ = writeln!(c_out, "{got}");
        let _ = writeln!(want, "{expected}");
        py_args.push(kind.to_string());
        py_args.push(file.display().to_string());
    }
    let py = Command::new("python3")
        .arg(dir.join("printer.py"))
        .arg(&dir)
        .args(&py_args)
        .output()
        .unwrap();
    assert!(
        py.status.success(),
        "python3: {}",
        String::from_utf8_lossy(&py.stderr)
    );
    let py_out = String::from_utf8_lossy(&py.stdout);
    for ((name, _, expected), got) in cases.iter().zip(py_out.lines()) {
        assert_eq!(got, expected, "Python on case {name:?}");
    }
    assert_eq!(py_out.lines().count(), cases.len());
}
