//! The layer rules of docs/architecture.md, read from the source: no module outside
//! `src/tools/` and `src/bin/` imports `crate::tools`, and no core module imports
//! `crate::ros`. Comments may name the layers; code may not reach them.

use std::fs;
use std::path::{Path, PathBuf};

/// The core: no ROS, no clock, no I/O.
const CORE: &[&str] = &[
    "adaptive",
    "config",
    "earth.rs",
    "engine",
    "eval.rs",
    "filter",
    "gnss",
    "ins",
    "linalg.rs",
    "sim",
];

fn rust_files(dir: &Path, into: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).expect("readable source folder") {
        let path = entry.expect("readable folder entry").path();
        if path.is_dir() {
            rust_files(&path, into);
        } else if path.extension().is_some_and(|e| e == "rs") {
            into.push(path);
        }
    }
}

/// `file:line: text` of every code line (comments left out) that names `path`.
fn code_lines_naming(files: &[PathBuf], path: &str) -> Vec<String> {
    let mut found = Vec::new();
    for file in files {
        let text = fs::read_to_string(file).expect("readable source file");
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.contains(path) {
                found.push(format!("{}:{}: {}", file.display(), i + 1, line.trim()));
            }
        }
    }
    found
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn only_the_tools_and_the_executables_import_the_tools() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.retain(|f| !f.starts_with(src().join("tools")) && !f.starts_with(src().join("bin")));
    assert!(files.len() > 100, "the source tree was not found");
    let found = code_lines_naming(&files, "crate::tools");
    assert!(
        found.is_empty(),
        "imports of crate::tools:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_core_does_not_import_the_ros_layer() {
    let mut files = Vec::new();
    for part in CORE {
        let path = src().join(part);
        if path.is_dir() {
            rust_files(&path, &mut files);
        } else {
            assert!(path.is_file(), "core module {part} not found");
            files.push(path);
        }
    }
    let found = code_lines_naming(&files, "crate::ros");
    assert!(
        found.is_empty(),
        "core imports of crate::ros:\n{}",
        found.join("\n")
    );
}
