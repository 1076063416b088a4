//! Helpers shared by the CLI's integration tests: the shared data sets and the
//! KF-GINS text files the commands write.

#![allow(dead_code)] // each test crate uses its own subset

use std::path::{Path, PathBuf};

/// A data set under `../shared/data/` (beside the checkout), which must exist.
pub fn shared_data(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(name);
    assert!(
        dir.is_dir(),
        "{} is missing: the shared data sets live beside the checkout",
        dir.display()
    );
    dir
}

/// The decompressed bytes of an `.xz` file.
pub fn unxz(path: &Path) -> Vec<u8> {
    let mut input = std::io::BufReader::new(std::fs::File::open(path).expect("open .xz"));
    let mut out = Vec::new();
    lzma_rs::xz_decompress(&mut input, &mut out).expect("xz");
    out
}

/// Rows of whitespace-separated numbers (KF-GINS text formats).
pub fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect()
        })
        .collect()
}

/// Rows of a KF-GINS text file.
pub fn read_rows(path: &Path) -> Vec<Vec<f64>> {
    rows(&std::fs::read_to_string(path).expect("read"))
}

/// Run `schuler simulate` on `examples/drive.toml` (the 20-minute example drive) into
/// `out`.
pub fn simulate_example_drive(out: &Path) {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive.toml");
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["simulate", "--config"])
        .arg(&example)
        .arg("--out")
        .arg(out)
        .assert()
        .success();
}
