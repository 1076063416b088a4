//! `schuler demo --quick`: the report exists and names every section, every plot has
//! axes with units, the inertial-satellite errors are below the free-inertial ones,
//! the summary table's numbers are the ones in the CSVs, and the same run gives the
//! same data bit for bit.

use assert_cmd::Command;
use schuler_cli::commands::demo::Sortie;
use std::path::Path;

fn run_demo(out: &Path) -> String {
    let output = Command::cargo_bin("schuler")
        .expect("binary")
        .args(["demo", "--quick", "--out"])
        .arg(out)
        .output()
        .expect("run");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("utf-8")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Rows of a CSV with a header, as strings.
fn rows(path: &Path) -> Vec<Vec<String>> {
    read(path)
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

const SECTIONS: [&str; 7] = [
    "sortie",
    "alignment",
    "inertial",
    "aided",
    "sensors",
    "vertical",
    "summary",
];

#[test]
fn quick_demo_report_is_complete_and_agrees_with_its_data() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("demo");
    let stdout = run_demo(&out);
    assert!(stdout.contains("report.html"), "{stdout}");
    let html = read(&out.join("report.html"));
    for s in SECTIONS {
        assert!(
            html.contains(&format!("<section id=\"{s}\">")),
            "section {s}"
        );
        assert!(
            html.contains(&format!("href=\"#{s}\"")),
            "contents entry {s}"
        );
    }
    // Every plot is embedded, and each has an x and a y label with a unit in brackets.
    let svgs: Vec<&str> = html.split("<svg").skip(1).collect();
    assert!(svgs.len() >= 10, "{} plots", svgs.len());
    for svg in &svgs {
        let body = &svg[..svg.find("</svg>").expect("closed")];
        let labelled = body
            .split("<text")
            .skip(1)
            .filter(|t| {
                let t = &t[..t.find("</text>").unwrap_or(t.len())];
                t.contains('[') && t.contains(']')
            })
            .count();
        assert!(labelled >= 2, "a plot lacks axis units");
    }

    let sortie = Sortie::quick().expect("quick sortie");
    let summary = rows(&out.join("summary.csv"));
    assert_eq!(summary.len(), 5);
    let by_mode = |label: &str| {
        summary
            .iter()
            .find(|r| r[0] == label)
            .unwrap_or_else(|| panic!("no {label} row"))
            .clone()
    };
    // Column 4: max dS in flight. GNSS aiding beats free inertial navigation, and the
    // smoother does no worse than the forward filter.
    let free = num(&by_mode("inertial with baro loop")[4]);
    let coarse = num(&by_mode("inertial after coarse alignment only")[4]);
    let forward = num(&by_mode("inertial-satellite forward")[4]);
    let smoothed = num(&by_mode("inertial-satellite smoothed")[4]);
    assert!(
        forward < free && forward < coarse,
        "{forward} vs {free}, {coarse}"
    );
    assert!(smoothed <= forward, "{smoothed} vs {forward}");

    let summary_html = &html[html.find("<section id=\"summary\">").expect("summary")..];
    for row in &summary {
        let errors = rows(&out.join(&row[8]));
        let at = |t: f64| {
            errors
                .iter()
                .find(|e| num(&e[0]) == t)
                .unwrap_or_else(|| panic!("no epoch {t} in {}", row[8]))
        };
        let last = errors.last().expect("rows");
        let flight = errors.iter().filter(|e| num(&e[0]) >= sortie.takeoff);
        let max = |col: usize| {
            flight
                .clone()
                .map(|e| num(&e[col]).abs())
                .fold(0.0, f64::max)
        };
        // Columns of errors_*.csv: t, north, east, circular, height, roll, pitch, yaw.
        assert_eq!(row[1], at(sortie.takeoff)[3], "{} take-off", row[0]);
        assert_eq!(row[2], at(sortie.outages[0].1)[3], "{} outage end", row[0]);
        assert_eq!(row[3], last[3], "{} end", row[0]);
        assert_eq!(row[4], format!("{:.3}", max(3)), "{} max dS", row[0]);
        assert_eq!(row[5], format!("{:.3}", max(4)), "{} max dh", row[0]);
        assert_eq!(row[6], last[7], "{} yaw", row[0]);
        // The report's table shows the same strings, in order.
        let mut rest = summary_html;
        for cell in row {
            let i = rest
                .find(&format!(">{cell}</td>"))
                .unwrap_or_else(|| panic!("{cell} of {} not in the report's table", row[0]));
            rest = &rest[i..];
        }
    }

    // Same seed, same data: a second run writes the same bytes (run times aside).
    let again = dir.path().join("again");
    run_demo(&again);
    for f in std::fs::read_dir(&out).expect("dir") {
        let name = f.expect("entry").file_name();
        let name = name.to_string_lossy();
        if name.starts_with("errors_") || name.starts_with("nav_") || name == "sensors.csv" {
            assert!(
                read(&out.join(&*name)) == read(&again.join(&*name)),
                "{name} differs between runs"
            );
        }
    }
}
