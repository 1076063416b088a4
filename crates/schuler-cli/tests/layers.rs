//! The house's rules (ARCHITECTURE.md), read from the manifests and the sources of the
//! checkout: each crate depends only on the layers below it, the Python package never
//! on the CLI, the formats crate on neither clap nor the application layer, and no CLI
//! function is longer than 80 lines. `.ci/run` checks the same dependencies again in
//! `cargo tree` (transitively, with the registry's crates).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The folder holding the workspace's crates.
fn crates_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("crates/")
        .to_path_buf()
}

/// Each crate of `crates/` (by folder name) with the names of its normal
/// dependencies, as its manifest lists them (`workspace = true` entries included).
fn dependencies() -> BTreeMap<String, BTreeSet<String>> {
    let mut all = BTreeMap::new();
    for entry in std::fs::read_dir(crates_dir()).expect("crates/") {
        let dir = entry.expect("entry").path();
        let manifest = dir.join("Cargo.toml");
        let Ok(text) = std::fs::read_to_string(&manifest) else {
            continue;
        };
        let table: toml::Table = toml::from_str(&text).expect("a manifest");
        let deps = table
            .get("dependencies")
            .and_then(toml::Value::as_table)
            .map(|t| t.keys().cloned().collect())
            .unwrap_or_default();
        let name = dir
            .file_name()
            .expect("name")
            .to_string_lossy()
            .into_owned();
        all.insert(name, deps);
    }
    all
}

/// The workspace crates `name` reaches through its dependencies (itself excluded).
fn reaches(all: &BTreeMap<String, BTreeSet<String>>, name: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![name.to_owned()];
    while let Some(n) = todo.pop() {
        for d in all.get(&n).into_iter().flatten() {
            if all.contains_key(d) && seen.insert(d.clone()) {
                todo.push(d.clone());
            }
        }
    }
    seen
}

#[test]
fn each_layer_depends_only_on_the_layers_below() {
    let all = dependencies();
    let set =
        |names: &[&str]| -> BTreeSet<String> { names.iter().map(|s| (*s).to_owned()).collect() };
    // The library knows no files; the formats only the library; the reports the
    // formats (to write whole files); the application layer all three.
    let allowed = [
        ("schuler", set(&[])),
        ("schuler-io", set(&["schuler"])),
        ("schuler-report", set(&["schuler", "schuler-io"])),
        (
            "schuler-run",
            set(&["schuler", "schuler-io", "schuler-report"]),
        ),
        (
            "schuler-py",
            set(&["schuler", "schuler-io", "schuler-report", "schuler-run"]),
        ),
    ];
    for (name, below) in allowed {
        let reached = reaches(&all, name);
        let beyond: Vec<_> = reached.difference(&below).collect();
        assert!(beyond.is_empty(), "{name} depends on {beyond:?}");
    }
    for (name, deps) in &all {
        assert!(
            name == "schuler-cli" || !reaches(&all, name).contains("schuler-cli"),
            "{name} depends on the CLI ({deps:?})"
        );
    }
    for name in ["schuler", "schuler-io", "schuler-report"] {
        assert!(!all[name].contains("clap"), "{name} depends on clap");
    }
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for entry in std::fs::read_dir(&d).expect("a folder") {
            let p = entry.expect("entry").path();
            if p.is_dir() {
                todo.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                files.push(p);
            }
        }
    }
    files.sort();
    files
}

#[test]
fn nothing_below_the_cli_names_it() {
    let crates = crates_dir();
    for name in [
        "schuler",
        "schuler-io",
        "schuler-report",
        "schuler-run",
        "schuler-py",
    ] {
        for file in sources(&crates.join(name).join("src")) {
            let text = std::fs::read_to_string(&file).expect("source");
            for (i, line) in text.lines().enumerate() {
                assert!(
                    !line.contains("schuler_cli"),
                    "{}:{}: names the CLI: {line}",
                    file.display(),
                    i + 1
                );
            }
        }
    }
}

/// The functions of `text` longer than `max` lines: name, first line and length. A
/// function runs from its `fn` line to the first line that closes it at the same
/// indentation (rustfmt's layout).
fn long_functions(text: &str, max: usize) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut long = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let body = line.trim_start();
        let indent = &line[..line.len() - body.len()];
        let after_vis = body
            .strip_prefix("pub(crate) ")
            .or_else(|| body.strip_prefix("pub(super) "))
            .or_else(|| body.strip_prefix("pub "))
            .unwrap_or(body);
        let Some(rest) = after_vis.strip_prefix("fn ") else {
            continue;
        };
        if line.trim_end().ends_with(';') {
            continue;
        }
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let close = format!("{indent}}}");
        if let Some(end) = lines[i + 1..].iter().position(|l| *l == close) {
            let n = end + 2;
            if n > max {
                long.push((name, i + 1, n));
            }
        }
    }
    long
}

#[test]
fn the_checker_measures_a_function() {
    let text = "fn short() {\n    1;\n}\n\nimpl A {\n    pub fn long() {\n        a();\n        b();\n    }\n}\n";
    assert_eq!(long_functions(text, 3), vec![("long".to_owned(), 6, 4)]);
    assert!(long_functions(text, 4).is_empty());
}

#[test]
fn no_cli_function_is_over_80_lines() {
    let mut long = Vec::new();
    for file in sources(&crates_dir().join("schuler-cli").join("src")) {
        let text = std::fs::read_to_string(&file).expect("source");
        for (name, line, n) in long_functions(&text, 80) {
            long.push(format!("{}:{line}: {name} ({n} lines)", file.display()));
        }
    }
    assert!(long.is_empty(), "CLI functions over 80 lines: {long:#?}");
}
