//! Every option declared once: each field of the request schema (`pipeline::request`) is
//! reachable from the CLI with the schema's default, a bad value gets the name table's error
//! there too, the C header's enum codes are the name tables' and 0 threads or 0 MiB mean the
//! defaults in the CLI and the C interface alike (Python's are in python/tests).
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;

use cli_support::{text, voxelkit};
use serde_json::Value;
use voxelkit::choice::Choice;
use voxelkit::implicit::Coordinates;
use voxelkit::io::vdb::Compression;
use voxelkit::ops::csg::BooleanOp;
use voxelkit::pipeline::request::{FillKind, SurfaceKind, schema};
use voxelkit::voxelize::separating::Criterion;

/// The subcommand whose flags fill each request.
const SUBCOMMANDS: [(&str, &[&str]); 10] = [
    ("mesh", &["mesh"]),
    ("solid", &["solid"]),
    ("measure", &["measure"]),
    ("subdiv", &["subdiv"]),
    ("implicit", &["implicit"]),
    ("lines", &["lines"]),
    ("combine", &["csg"]),
    ("to_mesh", &["to-mesh"]),
    ("limits", &["mesh"]),
    ("write", &["mesh"]),
];

/// Fields whose flag is not `--` and the field's name in kebab case.
const FLAGS: [(&str, &str, &str); 4] = [
    ("mesh", "colors", "--no-color"),
    ("lines", "colors", "--no-color"),
    ("combine", "op", "[OPERATION]"),
    ("limits", "max_memory_mib", "--max-memory"),
];

fn help(args: &[&str]) -> String {
    let mut all = args.to_vec();
    all.push("--help");
    let o = voxelkit(&all);
    assert!(o.status.success(), "{all:?}: {}", text(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The help line of `flag` (clap prints one line per option off a terminal, starting with
/// its short form, if any, and its name).
fn flag_line<'a>(help: &'a str, flag: &str) -> Option<&'a str> {
    help.lines().find(|l| {
        let t = l.trim_start();
        let t = match t.split_once(", ") {
            Some((short, rest)) if short.len() == 2 && short.starts_with('-') => rest,
            _ => t,
        };
        t.split(' ').next() == Some(flag)
    })
}

/// Whether the CLI's `[default: X]` says the schema's default.
fn same_default(shown: &str, schema: &Value) -> bool {
    let numbers = |s: &str| -> Option<Vec<f64>> {
        s.split(',').map(|p| p.trim().parse::<f64>().ok()).collect()
    };
    match schema {
        Value::String(s) => shown == s,
        Value::Number(n) => numbers(shown) == Some(vec![n.as_f64().unwrap()]),
        Value::Array(items) => {
            let flat: Option<Vec<f64>> = items.iter().map(Value::as_f64).collect();
            flat.is_some() && numbers(shown) == flat
        }
        _ => false,
    }
}

#[test]
fn every_schema_field_is_a_cli_flag_with_the_schema_default() {
    let schema = schema();
    let mut checked = 0;
    for (request, command) in SUBCOMMANDS {
        let text = help(command);
        for field in schema[request]["fields"].as_array().unwrap() {
            let name = field["name"].as_str().unwrap();
            let flag = FLAGS
                .iter()
                .find(|(r, f, _)| *r == request && *f == name)
                .map_or_else(
                    || format!("--{}", name.replace('_', "-")),
                    |t| t.2.to_string(),
                );
            let line = flag_line(&text, &flag).unwrap_or_else(|| {
                panic!("{request}.{name}: no {flag} in `voxelkit {command:?} --help`")
            });
            let default = &field["default"];
            let shown = line
                .rsplit_once("[default: ")
                .map(|(_, d)| d.trim_end().trim_end_matches(']'));
            match (default, shown) {
                // Flags that are off (or on, given as --no-x) and options left unset show no
                // default, or say what unset means.
                (Value::Bool(_) | Value::Null, _) => {}
                (Value::Array(a), _) if a.is_empty() => {}
                // A positional argument is given every time.
                _ if !flag.starts_with('-') => {}
                (d, Some(shown)) => assert!(
                    same_default(shown, d),
                    "{request}.{name}: the CLI's {flag} defaults to {shown}, the schema to {d}"
                ),
                (d, None) => {
                    panic!("{request}.{name}: {flag} shows no default (the schema's is {d})")
                }
            }
            checked += 1;
        }
    }
    assert!(checked > 60, "only {checked} fields checked");
}

#[test]
fn a_bad_choice_gets_the_name_tables_error_from_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.vdb");
    let out = out.to_str().unwrap();
    for (args, error) in [
        (
            vec!["mesh", "m.obj", "-s", "7"],
            "separability must be 6 or 26, not `7`",
        ),
        (
            vec!["mesh", "m.obj", "--criterion", "x"],
            &*Criterion::parse_choice("x").unwrap_err(),
        ),
        (
            vec!["solid", "m.obj", "--method", "x"],
            &*FillKind::parse_choice("x").unwrap_err(),
        ),
        (
            vec!["mesh", "m.obj", "--method", "x"],
            &*SurfaceKind::parse_choice("x").unwrap_err(),
        ),
        (
            vec!["subdiv", "m.obj", "-a", "7"],
            "the adjacency must be 6, 18 or 26, not `7`",
        ),
    ] {
        let mut all = args.clone();
        all.extend(["-o", out]);
        let o = voxelkit(&all);
        assert!(!o.status.success(), "{all:?}");
        assert!(text(&o).contains(error), "{all:?}: {}", text(&o));
    }
}

#[test]
fn zero_threads_and_zero_memory_mean_the_defaults_in_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.vdb");
    let o = voxelkit(&[
        "--json",
        "--threads",
        "0",
        "--max-memory",
        "0",
        "shape",
        "sphere",
        "-r",
        "32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(out.exists());
}

/// The `VK_...` names and values of the header's enum `name`.
fn header_enum(header: &str, name: &str) -> Vec<(String, i64)> {
    let start = header
        .find(&format!("typedef enum {name} {{"))
        .unwrap_or_else(|| panic!("no enum {name} in the header"));
    let body = &header[start..];
    let body = &body[body.find('{').unwrap() + 1..body.find('}').unwrap()];
    body.lines()
        .map(|l| l.split("/*").next().unwrap().trim().trim_end_matches(','))
        .filter_map(|l| l.split_once('='))
        .map(|(n, v)| (n.trim().to_string(), v.trim().parse().unwrap()))
        .collect()
}

/// Whether the header's enum `name` gives each value of `T` its code, as `prefix` + NAME.
fn check_codes<T: Choice>(header: &str, name: &str, prefix: &str) {
    let mut expected: Vec<(String, i64)> = T::NAMES
        .iter()
        .map(|(n, v)| {
            let id = format!("{prefix}{}", n.to_uppercase().replace('-', "_"));
            (id, v.code())
        })
        .collect();
    let mut found = header_enum(header, name);
    expected.sort();
    found.sort();
    assert_eq!(found, expected, "{name}: the header against the name table");
}

#[test]
fn the_c_headers_enum_codes_are_the_name_tables() {
    let header =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/voxelkit.h"))
            .unwrap();
    check_codes::<SurfaceKind>(&header, "vk_surface_method", "VK_SURFACE_");
    check_codes::<FillKind>(&header, "vk_fill_method", "VK_FILL_");
    check_codes::<Criterion>(&header, "vk_criterion", "VK_CRITERION_");
    check_codes::<Coordinates>(&header, "vk_coordinates", "VK_");
    check_codes::<BooleanOp>(&header, "vk_boolean", "VK_");
    check_codes::<Compression>(&header, "vk_compression", "VK_COMPRESSION_");
}

#[test]
fn library_messages_name_options_and_the_cli_says_its_flags() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for (r, name) in [("16", "a.vdb"), ("20", "b.vdb")] {
        let o = voxelkit(&["shape", "sphere", "-r", r, "-o", &path(name)]);
        assert!(o.status.success(), "{}", text(&o));
    }
    let o = voxelkit(&[
        "csg",
        "union",
        &path("a.vdb"),
        &path("b.vdb"),
        "-o",
        &path("c.vdb"),
    ]);
    assert!(!o.status.success());
    let said = text(&o);
    assert!(
        said.contains("(--resample)") && !said.contains("option `"),
        "{said}"
    );
    let a = voxelkit::io::vdb::read_vdb_grid(std::path::Path::new(&path("a.vdb")), None).unwrap();
    let b = voxelkit::io::vdb::read_vdb_grid(std::path::Path::new(&path("b.vdb")), None).unwrap();
    let e = voxelkit::ops::csg::combine(&a, &b, BooleanOp::Union, false).unwrap_err();
    assert!(e.to_string().contains("(option `resample`)"), "{e}");
}

#[test]
fn resolution_separability_and_voxel_sizes_are_typed_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let info = |file: &str| -> Value {
        let o = voxelkit(&["--json", "info", file]);
        assert!(o.status.success(), "{}", text(&o));
        let j: Value = serde_json::from_slice(&o.stdout).unwrap();
        j["grids"][0]["metadata"].clone()
    };
    let o = voxelkit(&[
        "shape",
        "sphere",
        "-r",
        "24",
        "-s",
        "6",
        "-o",
        &path("r.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let meta = info(&path("r.vdb"));
    assert_eq!(meta["resolution"], Value::from(24), "{meta}");
    assert_eq!(meta["separability"], Value::from(6), "{meta}");
    let o = voxelkit(&[
        "shape",
        "sphere",
        "--voxel-size",
        "0.125",
        "-o",
        &path("h.vdb"),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let meta = info(&path("h.vdb"));
    assert_eq!(meta["voxel_size"], Value::from(0.125), "{meta}");
    assert!(meta.get("resolution").is_none(), "{meta}");
}
