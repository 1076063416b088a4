//! Small self-contained SVG line plots: several series, a title, axis labels with units,
//! a legend, and optional shaded x-intervals (e.g. periods of prediction).
//!
//! No dependencies and no fonts to bundle: the SVG names a generic sans-serif family and
//! any browser or viewer renders it. Long series are thinned per pixel column keeping
//! each column's first, lowest, highest and last point, so envelopes survive. Non-finite
//! values break a line instead of corrupting it.
//!
//! ```
//! use schuler_report::plot::{LineStyle, Plot};
//! let t = [0.0, 1.0, 2.0];
//! let svg = Plot::new("Velocity error", "t [h]", "dV [m/s]")
//!     .line("nonlinear", &t, &[0.0, 0.5, 0.2], LineStyle::Solid)
//!     .line("closed form", &t, &[0.0, 0.49, 0.21], LineStyle::Dashed)
//!     .to_svg();
//! assert!(svg.starts_with("<svg") && svg.contains("dV [m/s]"));
//! ```

use crate::html::escape as esc;
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

/// Time axis: hours for runs of 2 h or more, minutes from 10 min, else seconds.
pub fn time_axis(duration: f64) -> (f64, &'static str) {
    if duration >= 7200.0 {
        (3600.0, "t [h]")
    } else if duration >= 600.0 {
        (60.0, "t [min]")
    } else {
        (1.0, "t [s]")
    }
}

/// How a series is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineStyle {
    /// Continuous line.
    Solid,
    /// Long dashes.
    Dashed,
    /// Dots.
    Dotted,
}

impl LineStyle {
    fn dasharray(self) -> Option<&'static str> {
        match self {
            LineStyle::Solid => None,
            LineStyle::Dashed => Some("8 5"),
            LineStyle::Dotted => Some("2 4"),
        }
    }

    /// The SVG attribute ` stroke-dasharray="…"`, empty for a solid line.
    fn dash_attribute(self) -> String {
        self.dasharray()
            .map(|d| format!(r#" stroke-dasharray="{d}""#))
            .unwrap_or_default()
    }
}

/// One named series of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in data units.
    pub points: Vec<(f64, f64)>,
    /// Stroke style.
    pub style: LineStyle,
}

/// A shaded x-interval with a legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Span {
    /// Start (x units).
    pub from: f64,
    /// End (x units).
    pub to: f64,
}

/// A line plot under construction; [`Plot::to_svg`] renders it.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    /// Title above the plot.
    pub title: String,
    /// X-axis label, with unit (e.g. `"t [h]"`).
    pub x_label: String,
    /// Y-axis label, with unit (e.g. `"alpha [arcsec]"`).
    pub y_label: String,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Shaded x-intervals.
    pub spans: Vec<Span>,
    /// Legend label of the shaded intervals.
    pub span_label: String,
    /// Width \[px\].
    pub width: u32,
    /// Height \[px\].
    pub height: u32,
}

const PALETTE: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
];
const LEFT: f64 = 84.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 56.0;

impl Plot {
    /// An empty 800x480 plot.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.to_owned(),
            x_label: x_label.to_owned(),
            y_label: y_label.to_owned(),
            series: Vec::new(),
            spans: Vec::new(),
            span_label: String::new(),
            width: 800,
            height: 480,
        }
    }

    /// Adds a series from parallel slices (extra elements of the longer one are ignored).
    pub fn line(mut self, label: &str, x: &[f64], y: &[f64], style: LineStyle) -> Self {
        self.series.push(Series {
            label: label.to_owned(),
            points: x.iter().copied().zip(y.iter().copied()).collect(),
            style,
        });
        self
    }

    /// Adds a series from optional values: `None` leaves a gap.
    pub fn line_opt(mut self, label: &str, x: &[f64], y: &[Option<f64>], style: LineStyle) -> Self {
        self.series.push(Series {
            label: label.to_owned(),
            points: x
                .iter()
                .zip(y)
                .map(|(&x, y)| (x, y.unwrap_or(f64::NAN)))
                .collect(),
            style,
        });
        self
    }

    /// Shades the x-intervals `spans`, listed once in the legend as `label`.
    pub fn shade(mut self, label: &str, spans: impl IntoIterator<Item = (f64, f64)>) -> Self {
        self.span_label = label.to_owned();
        self.spans
            .extend(spans.into_iter().map(|(from, to)| Span { from, to }));
        self
    }

    /// Writes the SVG to `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        schuler_io::line_file::write_whole(path, self.to_svg())
    }

    /// Renders the plot as a standalone SVG document.
    pub fn to_svg(&self) -> String {
        let f = Frame::new(self);
        let mut s = String::with_capacity(64 * 1024);
        self.write_head(&mut s, &f);
        self.write_spans(&mut s, &f);
        f.write_grid(&mut s);
        self.write_axes(&mut s, &f);
        self.write_series(&mut s, &f);
        self.write_legend(&mut s, &f);
        s.push_str("</svg>\n");
        s
    }

    /// The document's opening tag, the white background and the title.
    fn write_head(&self, s: &mut String, f: &Frame) {
        let (w, h) = (f.w, f.h);
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
        let _ = writeln!(
            s,
            r#"<text x="{}" y="24" text-anchor="middle" font-size="15">{}</text>"#,
            LEFT + f.pw / 2.0,
            esc(&self.title)
        );
    }

    /// The shaded spans, clipped to the plot area.
    fn write_spans(&self, s: &mut String, f: &Frame) {
        for span in &self.spans {
            let (a, b) = (f.sx(span.from.max(f.x0)), f.sx(span.to.min(f.x1)));
            if b > a {
                let _ = writeln!(
                    s,
                    r##"<rect x="{a:.1}" y="{TOP}" width="{:.1}" height="{}" fill="#999999" fill-opacity="0.18"/>"##,
                    b - a,
                    f.ph
                );
            }
        }
    }

    /// The plot area's frame and the axis labels.
    fn write_axes(&self, s: &mut String, f: &Frame) {
        let _ = writeln!(
            s,
            r#"<rect x="{LEFT}" y="{TOP}" width="{}" height="{}" fill="none" stroke="black"/>"#,
            f.pw, f.ph
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            LEFT + f.pw / 2.0,
            f.h - 12.0,
            esc(&self.x_label)
        );
        let _ = writeln!(
            s,
            r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">{}</text>"#,
            TOP + f.ph / 2.0,
            TOP + f.ph / 2.0,
            esc(&self.y_label)
        );
    }

    /// Each series, thinned per pixel column: a polyline per run of finite points, a
    /// dot for a lone point.
    fn write_series(&self, s: &mut String, f: &Frame) {
        for (i, series) in self.series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let dash = series.style.dash_attribute();
            for run in thin(&series.points, f.x0, f.x1, f.pw as usize) {
                if run.len() == 1 {
                    let (x, y) = run[0];
                    let _ = writeln!(
                        s,
                        r#"<circle cx="{:.2}" cy="{:.2}" r="1.5" fill="{color}"/>"#,
                        f.sx(x),
                        f.sy(y)
                    );
                    continue;
                }
                let _ = write!(
                    s,
                    r#"<polyline fill="none" stroke="{color}" stroke-width="1.6"{dash} points=""#
                );
                for (x, y) in run {
                    let _ = write!(s, "{:.2},{:.2} ", f.sx(x), f.sy(y));
                }
                let _ = writeln!(s, r#""/>"#);
            }
        }
    }

    /// The legend's entries: each series' label and stroke, then the shaded spans'
    /// label (empty stroke).
    fn legend_entries(&self) -> Vec<(String, String)> {
        let mut entries: Vec<(String, String)> = self
            .series
            .iter()
            .enumerate()
            .map(|(i, se)| {
                let color = PALETTE[i % PALETTE.len()];
                let dash = se.style.dash_attribute();
                (
                    se.label.clone(),
                    format!(r#"stroke="{color}" stroke-width="2"{dash}"#),
                )
            })
            .collect();
        if !self.spans.is_empty() && !self.span_label.is_empty() {
            entries.push((self.span_label.clone(), String::new()));
        }
        entries
    }

    /// The legend, top right inside the frame: a box sized to the longest label, a
    /// stroke sample (or a shaded swatch) and the label per entry.
    fn write_legend(&self, s: &mut String, f: &Frame) {
        let entries = self.legend_entries();
        if entries.is_empty() {
            return;
        }
        let longest = entries
            .iter()
            .map(|e| e.0.chars().count())
            .max()
            .unwrap_or(0) as f64;
        let bw = 40.0 + 7.0 * longest;
        let bh = 8.0 + 18.0 * entries.len() as f64;
        let bx = LEFT + f.pw - bw - 8.0;
        let by = TOP + 8.0;
        let _ = writeln!(
            s,
            r##"<rect x="{bx:.1}" y="{by:.1}" width="{bw:.1}" height="{bh:.1}" fill="white" fill-opacity="0.9" stroke="#888888"/>"##
        );
        for (k, (text, stroke)) in entries.iter().enumerate() {
            let y = by + 16.0 + 18.0 * k as f64;
            if stroke.is_empty() {
                let _ = writeln!(
                    s,
                    r##"<rect x="{:.1}" y="{:.1}" width="24" height="10" fill="#999999" fill-opacity="0.3"/>"##,
                    bx + 8.0,
                    y - 8.0
                );
            } else {
                let _ = writeln!(
                    s,
                    r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" {stroke}/>"#,
                    bx + 8.0,
                    y - 4.0,
                    bx + 32.0,
                    y - 4.0
                );
            }
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{y:.1}">{}</text>"#,
                bx + 38.0,
                esc(text)
            );
        }
    }
}

/// The plot area in data and in pixels: the ranges (finite points widened, 5 % in y,
/// and extended to whole ticks), the ticks, and the map from data to pixels.
struct Frame {
    /// Document width and height \[px\].
    w: f64,
    h: f64,
    /// Plot-area width and height \[px\].
    pw: f64,
    ph: f64,
    /// X range (data units).
    x0: f64,
    x1: f64,
    /// Y range (data units).
    y0: f64,
    y1: f64,
    /// Tick values.
    xt: Vec<f64>,
    yt: Vec<f64>,
}

impl Frame {
    /// The frame of `plot`'s size around its finite points.
    fn new(plot: &Plot) -> Self {
        let (w, h) = (f64::from(plot.width), f64::from(plot.height));
        let finite = plot
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| x.is_finite() && y.is_finite());
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in finite {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let (x0, x1) = widen(x0, x1, 0.0);
        let (y0, y1) = widen(y0, y1, 0.05);
        let xt = ticks(x0, x1, 8);
        let yt = ticks(y0, y1, 7);
        Self {
            w,
            h,
            pw: w - LEFT - RIGHT,
            ph: h - TOP - BOTTOM,
            x0: x0.min(xt[0]),
            x1: x1.max(*xt.last().unwrap_or(&x1)),
            y0: y0.min(yt[0]),
            y1: y1.max(*yt.last().unwrap_or(&y1)),
            xt,
            yt,
        }
    }

    /// Pixel column of `x`.
    fn sx(&self, x: f64) -> f64 {
        LEFT + (x - self.x0) / (self.x1 - self.x0) * self.pw
    }

    /// Pixel row of `y` (up is smaller).
    fn sy(&self, y: f64) -> f64 {
        TOP + (self.y1 - y) / (self.y1 - self.y0) * self.ph
    }

    /// The grid lines and tick labels of both axes.
    fn write_grid(&self, s: &mut String) {
        let (pw, ph) = (self.pw, self.ph);
        for &v in &self.xt {
            let x = self.sx(v);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{}" stroke="#e0e0e0"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
                TOP + ph,
                TOP + ph + 16.0,
                label(v, &self.xt)
            );
        }
        for &v in &self.yt {
            let y = self.sy(v);
            let _ = writeln!(
                s,
                r##"<line x1="{LEFT}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#e0e0e0"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
                LEFT + pw,
                LEFT - 6.0,
                y + 4.0,
                label(v, &self.yt)
            );
        }
    }
}

/// A non-degenerate range: equal ends are widened by 1 (or 10 % of the value); empty
/// ranges become [0, 1]; `pad` widens by that fraction on both sides.
fn widen(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    if hi <= lo {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let d = (hi - lo) * pad;
    (lo - d, hi + d)
}

/// About `target` round tick values (1, 2, 5 times a power of ten) covering [lo, hi].
pub fn ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    let raw = (hi - lo) / target.max(1) as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return vec![lo, hi];
    }
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).floor() as i64;
    let last = (hi / step).ceil() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Tick label with as many decimals as the tick step needs; exponent form for very
/// large or small magnitudes.
fn label(v: f64, all: &[f64]) -> String {
    let step = if all.len() > 1 {
        (all[1] - all[0]).abs()
    } else {
        1.0
    };
    let big = all.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if v == 0.0 {
        return "0".to_owned();
    }
    if !(1e-3..1e6).contains(&big) {
        let digits = ((big / step).log10().ceil().max(1.0) as usize).min(6);
        return format!("{:.*e}", digits.saturating_sub(1), v);
    }
    // A step of 0 (a constant series) needs no decimals; no f64 needs more than 17.
    let decimals = if step > 0.0 {
        (-step.log10().floor()).clamp(0.0, 17.0) as usize
    } else {
        0
    };
    format!("{v:.decimals$}")
}

/// Splits a series at non-finite points into runs and thins each run to at most four
/// points per pixel column (first, min, max, last, in x order).
fn thin(points: &[(f64, f64)], x0: f64, x1: f64, columns: usize) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for &(x, y) in points {
        if x.is_finite() && y.is_finite() {
            cur.push((x, y));
        } else if !cur.is_empty() {
            runs.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        runs.push(cur);
    }
    let columns = columns.max(1);
    runs.into_iter()
        .map(|run| {
            if run.len() <= 4 * columns {
                return run;
            }
            let col = |x: f64| (((x - x0) / (x1 - x0)) * columns as f64).floor() as i64;
            let mut out = Vec::with_capacity(4 * columns);
            let mut start = 0;
            while start < run.len() {
                let c = col(run[start].0);
                let mut end = start;
                while end < run.len() && col(run[end].0) == c {
                    end += 1;
                }
                let bucket = &run[start..end];
                let (mut imin, mut imax) = (0, 0);
                for (i, p) in bucket.iter().enumerate() {
                    if p.1 < bucket[imin].1 {
                        imin = i;
                    }
                    if p.1 > bucket[imax].1 {
                        imax = i;
                    }
                }
                let mut keep = vec![0, imin, imax, bucket.len() - 1];
                keep.sort_unstable();
                keep.dedup();
                out.extend(keep.into_iter().map(|i| bucket[i]));
                start = end;
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant series gives a tick step of 0: its labels need no decimals (this
    /// formatted with `usize::MAX` decimals and panicked).
    #[test]
    fn labels_of_a_constant_series() {
        assert_eq!(label(1000.0, &[1000.0, 1000.0]), "1000");
        assert_eq!(label(-1000.0, &[-1000.0]), "-1000");
    }

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        let t = ticks(-0.013, 0.87, 7);
        assert!(t[0] <= -0.013 && *t.last().unwrap() >= 0.87);
        let step = t[1] - t[0];
        assert!((step - 0.2).abs() < 1e-12, "{t:?}");
    }

    #[test]
    fn long_series_are_thinned_but_keep_extremes() {
        let pts: Vec<(f64, f64)> = (0..100_000)
            .map(|k| {
                (
                    k as f64,
                    if k == 51_234 {
                        1e3
                    } else {
                        (k as f64 * 0.01).sin()
                    },
                )
            })
            .collect();
        let runs = thin(&pts, 0.0, 99_999.0, 700);
        assert_eq!(runs.len(), 1);
        assert!(runs[0].len() <= 2800);
        assert!(runs[0].iter().any(|p| p.1 == 1e3));
    }

    #[test]
    fn nan_breaks_the_line_and_labels_are_escaped() {
        let svg = Plot::new("a < b & c", "t [s]", "x [m]")
            .line(
                "s",
                &[0.0, 1.0, 2.0, 3.0, 4.0],
                &[0.0, 1.0, f64::NAN, 2.0, 3.0],
                LineStyle::Dotted,
            )
            .shade("predict", [(1.0, 2.0)])
            .to_svg();
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("a &lt; b &amp; c"));
        assert!(svg.contains("predict"));
    }
}
