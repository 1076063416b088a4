//! `schuler demo --quick`: the report exists and names every section, every plot has
//! axes with units, the inertial-satellite errors are below the free-inertial ones,
//! the summary tables' numbers are the ones in the CSVs, the flight across the pole
//! passes over it with its aided error bounded, and the same run gives the same data
//! bit for bit.

use assert_cmd::Command;
use schuler_run::demo::{Crossing, Sortie};
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

/// The row whose first cell is `label`.
fn row_of(table: &[Vec<String>], label: &str) -> Vec<String> {
    table
        .iter()
        .find(|r| r[0] == label)
        .unwrap_or_else(|| panic!("no {label} row"))
        .clone()
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

const SECTIONS: [&str; 9] = [
    "sortie",
    "alignment",
    "inertial",
    "figure3",
    "aided",
    "sensors",
    "vertical",
    "polar",
    "summary",
];

/// `cells` appear in the report's HTML after `from`, in order, each as a table cell.
fn in_table_in_order(html: &str, from: &str, cells: &[String]) {
    let mut rest = &html[html.find(from).unwrap_or_else(|| panic!("no {from}"))..];
    for cell in cells {
        let i = rest
            .find(&format!(">{cell}</td>"))
            .unwrap_or_else(|| panic!("{cell} of {} not in the report's table", cells[0]));
        rest = &rest[i..];
    }
}

/// The `errors_*.csv` row at time `t` (column 0), and the largest `|value|` of column
/// `col` over the rows at or after `from`.
struct ErrorsCsv(Vec<Vec<String>>);

impl ErrorsCsv {
    fn at(&self, t: f64) -> &[String] {
        self.0
            .iter()
            .find(|e| num(&e[0]) == t)
            .unwrap_or_else(|| panic!("no epoch {t}"))
    }

    fn max_from(&self, from: f64, col: usize) -> String {
        let max = self
            .0
            .iter()
            .filter(|e| num(&e[0]) >= from)
            .map(|e| num(&e[col]).abs())
            .fold(0.0, f64::max);
        format!("{max:.3}")
    }
}

/// Every section is in the report and in its contents, and every embedded plot has an
/// x and a y label with a unit in brackets.
fn assert_sections_and_plot_units(html: &str) {
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
}

/// The sortie's summary: GNSS aiding beats free inertial navigation, the smoother does
/// no worse than the forward filter, and each row's numbers are its errors CSV's and
/// the report table's.
fn assert_sortie_summary(out: &Path, html: &str, sortie: &Sortie) {
    let summary = rows(&out.join("summary.csv"));
    assert_eq!(summary.len(), 5);
    let by_mode = |label: &str| row_of(&summary, label);
    // Column 4: max dS in flight.
    let free = num(&by_mode("inertial with baro loop")[4]);
    let coarse = num(&by_mode("inertial after coarse alignment only")[4]);
    let forward = num(&by_mode("inertial-satellite forward")[4]);
    let smoothed = num(&by_mode("inertial-satellite smoothed")[4]);
    assert!(
        forward < free && forward < coarse,
        "{forward} vs {free}, {coarse}"
    );
    assert!(smoothed <= forward, "{smoothed} vs {forward}");
    for row in &summary {
        let errors = ErrorsCsv(rows(&out.join(&row[8])));
        let last = errors.0.last().expect("rows");
        // Columns of errors_*.csv: t, north, east, circular, height, roll, pitch, yaw.
        assert_eq!(row[1], errors.at(sortie.takeoff)[3], "{} take-off", row[0]);
        assert_eq!(
            row[2],
            errors.at(sortie.outages[0].1)[3],
            "{} outage end",
            row[0]
        );
        assert_eq!(row[3], last[3], "{} end", row[0]);
        assert_eq!(
            row[4],
            errors.max_from(sortie.takeoff, 3),
            "{} max dS",
            row[0]
        );
        assert_eq!(
            row[5],
            errors.max_from(sortie.takeoff, 4),
            "{} max dh",
            row[0]
        );
        assert_eq!(row[6], last[7], "{} yaw", row[0]);
        // The report's table shows the same strings, in order.
        in_table_in_order(html, "<section id=\"summary\">", row);
    }
}

/// The crossing's own table (`polar_summary.csv`), each row equal to its errors CSV
/// and to the report's table; returns its rows.
fn assert_polar_summary(out: &Path, html: &str, crossing: &Crossing) -> Vec<Vec<String>> {
    let polar = rows(&out.join("polar_summary.csv"));
    assert_eq!(polar.len(), 4);
    for row in &polar {
        let errors = ErrorsCsv(rows(&out.join(&row[8])));
        let last = errors.0.last().expect("rows");
        assert_eq!(
            row[1],
            errors.at(crossing.outage.0)[3],
            "{} outage start",
            row[0]
        );
        assert_eq!(row[2], errors.at(crossing.t_pole())[3], "{} pole", row[0]);
        assert_eq!(
            row[3],
            errors.at(crossing.outage.1)[3],
            "{} outage end",
            row[0]
        );
        assert_eq!(row[4], last[3], "{} end", row[0]);
        assert_eq!(row[5], errors.max_from(crossing.t0, 3), "{} max dS", row[0]);
        assert_eq!(row[6], errors.max_from(crossing.t0, 4), "{} max dh", row[0]);
        in_table_in_order(html, "<section id=\"polar\">", row);
    }
    polar
}

/// The truth passes over the pole itself, and GNSS aiding beats free inertial
/// navigation across it with its error bounded (see the bound's derivation inside).
fn assert_pole_crossing(out: &Path, polar: &[Vec<String>], crossing: &Crossing) {
    // The truth's epoch at t_pole is on the axis (the track's x, y in km, 4 decimals:
    // within 0.1 m).
    let track = rows(&out.join("polar_track.csv"));
    let over = track
        .iter()
        .find(|r| num(&r[0]) == crossing.t_pole())
        .expect("epoch at the pole");
    assert!(num(&over[1]).hypot(num(&over[2])) <= 1e-4, "{over:?}");
    // Outside the outage a filter is at least as good as one fix: 3 sigma of a fix's
    // horizontal error, 3 sqrt(1.5^2 + 1.5^2) = 6.4 m. At the outage's end it has
    // drifted for 60 s from there: at most a fix's 3-sigma horizontal velocity error,
    // 3 sqrt(2) 0.05 m/s x 60 s = 12.7 m, plus 1/2 (g theta + b) t^2 with the hand-over's
    // 1 arcmin level uncertainty theta (the filter only improves on it) and an
    // unestimated 50 ug navigation-grade accelerometer bias b: 6.0 m; 25.1 m in all,
    // held for 5 s after the outage while the first fixes pull the drift back.
    let by_label = |label: &str| row_of(polar, label);
    let free = num(&by_label("wander inertial with baro loop")[5]);
    let aided = by_label("wander inertial-satellite forward");
    let smoothed = num(&by_label("wander inertial-satellite smoothed")[5]);
    assert!(num(&aided[5]) < free, "{aided:?} vs {free}");
    assert!(smoothed <= num(&aided[5]), "{smoothed} vs {aided:?}");
    let fix_3sigma = 3.0 * 1.5f64.hypot(1.5);
    let drift = 3.0 * 2f64.sqrt() * 0.05 * 60.0
        + 0.5 * (9.81 * (1.0f64 / 60.0).to_radians() + 50e-6 * 9.81) * 60.0 * 60.0;
    let errors = ErrorsCsv(rows(&out.join(&aided[8])));
    for e in &errors.0 {
        let (t, ds) = (num(&e[0]), num(&e[3]));
        let bound = if t > crossing.outage.0 && t <= crossing.outage.1 + 5.0 {
            fix_3sigma + drift
        } else {
            fix_3sigma
        };
        assert!(ds < bound, "dS {ds} m at {t} s above {bound} m");
    }
}

/// Same seed, same data: the data files of `out` and `again` are the same bytes (run
/// times aside).
/// Figure 3 against figure 2 (`figure3.csv`): three legs of equal length, each row's
/// largest circular error is its errors CSV's over the leg, and the closed forms'
/// terms add up to a bound that holds.
fn assert_figure3(out: &Path, html: &str) {
    let legs = rows(&out.join("figure3.csv"));
    let keys = ["inertial_coarse", "inertial", "inertial_fig3"];
    assert_eq!(legs.len(), keys.len());
    let fig3 = ErrorsCsv(rows(&out.join("errors_inertial_fig3.csv")));
    let end = fig3.0.last().map(|r| num(&r[0])).expect("epochs");
    let length = end - num(&legs[2][1]);
    for (leg, key) in legs.iter().zip(keys) {
        let errors = ErrorsCsv(rows(&out.join(format!("errors_{key}.csv"))));
        let t0 = num(&leg[1]);
        let max = errors
            .0
            .iter()
            .filter(|e| num(&e[0]) >= t0 && num(&e[0]) <= t0 + length)
            .map(|e| num(&e[3]))
            .fold(0.0, f64::max);
        assert_eq!(leg[14], format!("{max:.3}"), "{key}");
        let terms: f64 = leg[7..13].iter().map(|x| num(x)).sum();
        // Six terms rounded to the millimetre: within 3 mm.
        assert!(
            (terms - num(&leg[13])).abs() < 0.01,
            "{key}: terms {terms} vs bound {}",
            leg[13]
        );
        assert!(
            num(&leg[13]) >= max,
            "{key}: the bound {} under the error {max}",
            leg[13]
        );
    }
    in_table_in_order(html, "id=\"figure3\"", &legs[2]);
}

fn assert_same_data(out: &Path, again: &Path) {
    for f in std::fs::read_dir(out).expect("dir") {
        let name = f.expect("entry").file_name();
        let name = name.to_string_lossy();
        let data = name.starts_with("errors_")
            || name.starts_with("nav_")
            || name == "sensors.csv"
            || name == "polar_track.csv"
            || name == "polar_azimuth.csv";
        if data {
            assert!(
                read(&out.join(&*name)) == read(&again.join(&*name)),
                "{name} differs between runs"
            );
        }
    }
}

#[test]
fn quick_demo_report_is_complete_and_agrees_with_its_data() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("demo");
    let stdout = run_demo(&out);
    assert!(stdout.contains("report.html"), "{stdout}");
    let html = read(&out.join("report.html"));
    assert_sections_and_plot_units(&html);
    let sortie = Sortie::quick().expect("quick sortie");
    assert_sortie_summary(&out, &html, &sortie);
    assert_figure3(&out, &html);
    let crossing = Crossing::quick(&sortie).expect("quick crossing");
    let polar = assert_polar_summary(&out, &html, &crossing);
    assert_pole_crossing(&out, &polar, &crossing);
    let again = dir.path().join("again");
    run_demo(&again);
    assert_same_data(&out, &again);
}
