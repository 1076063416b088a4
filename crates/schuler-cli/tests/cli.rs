//! The CLI's integration tests, in one test binary: each module is one file beside
//! this one (its own doc says what it checks). One binary, not one per file, so that
//! what they share (the library's and the readers' generic code they call, the test
//! crates' own dependencies) is compiled, optimized and linked once; the modules'
//! paths name the tests (`cargo test -p schuler-cli --test cli fuzz::`).
//! `bag_python` stays its own binary: CI runs it alone with its Python packages.

mod common;

mod aided_cli;
mod align_cli;
mod allan_cli;
mod bag_cli;
mod bag_ros1;
mod budget_cli;
mod calibration_cli;
mod channel_cli;
mod compare_cli;
mod demo_cli;
mod drive9min;
mod errors_cli;
mod fuzz;
mod gnss_cli;
mod gnss_files_cli;
mod gnss_formats_cli;
mod gnss_stations;
mod imu_layouts_cli;
mod init_gnss_cli;
mod inspect_cli;
#[cfg(unix)]
mod interrupt_cli;
mod layers;
mod montecarlo_cli;
mod nav_cli;
mod nav_mechanization;
mod platform_cli;
mod reliability3_cli;
mod reliability_cli;
mod report_cli;
mod seed18_cli;
mod simulate_cli;
mod tight_drive_cli;
mod vehicle_cli;
mod vertical_cli;

/// Every test file beside this one is one of its modules (or `bag_python`'s own
/// binary): with `autotests = false` a file left out would never be compiled or run.
#[test]
fn every_test_file_is_a_module_here() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let root = std::fs::read_to_string(dir.join("cli.rs")).expect("tests/cli.rs");
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("tests/") {
        let name = entry
            .expect("entry")
            .file_name()
            .to_string_lossy()
            .into_owned();
        let Some(stem) = name.strip_suffix(".rs") else {
            continue;
        };
        if !matches!(stem, "cli" | "bag_python") && !root.contains(&format!("\nmod {stem};")) {
            missing.push(name);
        }
    }
    assert!(
        missing.is_empty(),
        "tests/{missing:?} not compiled: add `mod NAME;` to tests/cli.rs (and `use crate::common;` for `mod common;` in the file)"
    );
}
