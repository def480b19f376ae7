//! The library's layers: a module may use the modules below it, never one above it (so
//! voxelization does not reach into solids, nor operations into the pipeline). A `crate::`
//! path in code that points upwards fails this test, naming the file and the line.

use std::path::Path;

/// The top-level modules from the bottom up; modules on one rank may not use each other.
const LAYERS: [&[&str]; 15] = [
    &["error"],
    &[
        "system",
        "huge_pages",
        "mapped_bytes",
        "progress",
        "random",
        "choice",
    ],
    &["parallel_concat"],
    &["grid"],
    &["contour"],
    &["ffi"],
    &["io"],
    &["mesh"],
    &["shapes"],
    &["implicit", "subd"],
    &["voxelize"],
    &["ops"],
    &["solids"],
    &["pipeline"],
    &["capi", "python"],
];

fn rank(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// The top-level module a source file belongs to.
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    Some(first.trim_end_matches(".rs").to_string())
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn no_module_uses_a_higher_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut violations = Vec::new();
    let mut checked = 0;
    for file in files {
        let Some(module) = module_of(&src, &file) else {
            continue;
        };
        let Some(own) = rank(&module) else {
            // lib.rs and the binaries are not library layers.
            assert!(
                matches!(module.as_str(), "lib" | "bin"),
                "{}: the module `{module}` has no layer in tests/layering.rs",
                file.display()
            );
            continue;
        };
        checked += 1;
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap();
            for (at, _) in code.match_indices("crate::") {
                let used: String = code[at + 7..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let Some(theirs) = rank(&used) else {
                    continue;
                };
                if used != module && theirs >= own {
                    violations.push(format!(
                        "{}:{}: `{module}` uses `{used}` (a layer not below it)",
                        file.display(),
                        n + 1
                    ));
                }
            }
        }
    }
    assert!(checked > 50, "only {checked} files checked");
    assert!(violations.is_empty(), "\n{}", violations.join("\n"));
}
