//! Self-contained HTML reports: a title, numbered sections listed in a table of contents,
//! paragraphs, tables, preformatted text and plots embedded as inline SVG.
//!
//! One file, no scripts, no fonts, no external resources: it opens offline in any
//! browser. Every text the caller gives is escaped here; numbers are formatted by the
//! caller (the report does not guess precision). Each plot keeps its axis labels, which
//! by the project's convention carry a unit in brackets (`"t [s]"`, `"NIS [-]"`);
//! [`Report::plots_missing_units`] lists the plots that break it.
//!
//! ```
//! use schuler_report::plot::{LineStyle, Plot};
//! use schuler_report::html::{Report, Table};
//! let mut report = Report::new("Aided navigation <run 1>");
//! report.paragraph("Forward filter, 15 states.");
//! let errors = report.section("errors", "Position error");
//! errors.paragraph("Against the simulator's truth.");
//! errors.table(
//!     Table::new(["", "RMS [m]", "max [m]"])
//!         .row(["horizontal", "0.021", "0.085"])
//!         .row(["vertical", "0.030", "0.112"]),
//! );
//! errors.plot(
//!     &Plot::new("Horizontal error", "t [s]", "dH [m]")
//!         .line("filter", &[0.0, 1.0], &[0.02, 0.03], LineStyle::Solid),
//! );
//! let html = report.to_html();
//! assert!(html.contains("&lt;run 1&gt;") && html.contains(r#"<section id="errors">"#));
//! assert!(report.plots_missing_units().is_empty());
//! ```

use crate::plot::Plot;
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

/// A table: a header row and body rows of preformatted cells.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// Caption above the table (empty: none).
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Body rows; a row shorter than the header is padded with empty cells.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column headings and no rows.
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Self {
            caption: String::new(),
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    /// Sets the caption.
    pub fn caption(mut self, caption: &str) -> Self {
        caption.clone_into(&mut self.caption);
        self
    }

    /// Appends a row of cells (numbers already formatted by the caller).
    pub fn row<S: Into<String>>(mut self, cells: impl IntoIterator<Item = S>) -> Self {
        self.rows.push(cells.into_iter().map(Into::into).collect());
        self
    }
}

/// A plot embedded as inline SVG, with the relative paths of the files behind it.
#[derive(Debug, Clone, PartialEq)]
struct Figure {
    title: String,
    x_label: String,
    y_label: String,
    svg: String,
    files: Vec<String>,
}

/// One piece of a section's content, in order.
#[derive(Debug, Clone, PartialEq)]
enum Block {
    Paragraph(String),
    Subheading(String),
    Preformatted(String),
    Table(Table),
    Figure(Figure),
}

/// A section of a report: an anchor id, a heading and its blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    id: String,
    heading: String,
    blocks: Vec<Block>,
}

impl Section {
    /// The section's anchor id (as made unique by [`Report::section`]).
    pub fn id(&self) -> &str {
        &self.id
    }

    /// Appends a paragraph of plain text.
    pub fn paragraph(&mut self, text: &str) -> &mut Self {
        self.blocks.push(Block::Paragraph(text.to_owned()));
        self
    }

    /// Appends a subheading (not listed in the table of contents).
    pub fn subheading(&mut self, text: &str) -> &mut Self {
        self.blocks.push(Block::Subheading(text.to_owned()));
        self
    }

    /// Appends preformatted text (a command line, a log excerpt), shown in monospace.
    pub fn preformatted(&mut self, text: &str) -> &mut Self {
        self.blocks.push(Block::Preformatted(text.to_owned()));
        self
    }

    /// Appends a table.
    pub fn table(&mut self, table: Table) -> &mut Self {
        self.blocks.push(Block::Table(table));
        self
    }

    /// Embeds a plot as inline SVG.
    pub fn plot(&mut self, plot: &Plot) -> &mut Self {
        self.plot_with_files(plot, &[])
    }

    /// Embeds a plot and links the files behind it (relative paths such as
    /// `"nis_gnss_pos.svg"`, `"innovations.csv"`), listed under the figure.
    pub fn plot_with_files(&mut self, plot: &Plot, files: &[&str]) -> &mut Self {
        self.blocks.push(Block::Figure(Figure {
            title: plot.title.clone(),
            x_label: plot.x_label.clone(),
            y_label: plot.y_label.clone(),
            svg: plot.to_svg(),
            files: files.iter().map(|&f| f.to_owned()).collect(),
        }));
        self
    }
}

/// A report under construction; [`Report::to_html`] renders it as one HTML document.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    title: String,
    intro: Vec<String>,
    sections: Vec<Section>,
}

impl Report {
    /// An empty report with this title (shown as the page title and the top heading).
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_owned(),
            intro: Vec::new(),
            sections: Vec::new(),
        }
    }

    /// Appends a paragraph to the introduction, above the table of contents.
    pub fn paragraph(&mut self, text: &str) -> &mut Self {
        self.intro.push(text.to_owned());
        self
    }

    /// Appends a section and returns it to be filled. The id is reduced to
    /// `[a-z0-9_-]` (other characters become `-`, empty becomes `section`) and made
    /// unique with a `-2`, `-3`... suffix, so any caller string gives a valid anchor.
    pub fn section(&mut self, id: &str, heading: &str) -> &mut Section {
        let base = slug(id);
        let mut unique = base.clone();
        let mut k = 2;
        while self.sections.iter().any(|s| s.id == unique) {
            unique = format!("{base}-{k}");
            k += 1;
        }
        self.sections.push(Section {
            id: unique,
            heading: heading.to_owned(),
            blocks: Vec::new(),
        });
        let last = self.sections.len() - 1;
        &mut self.sections[last]
    }

    /// The sections, in order.
    pub fn sections(&self) -> &[Section] {
        &self.sections
    }

    /// Titles of the embedded plots whose x or y label has no unit in brackets
    /// (`"t [s]"` has one, `"time"` has not); empty when every plot is labelled.
    pub fn plots_missing_units(&self) -> Vec<String> {
        self.sections
            .iter()
            .flat_map(|s| &s.blocks)
            .filter_map(|b| match b {
                Block::Figure(f) if !(has_unit(&f.x_label) && has_unit(&f.y_label)) => {
                    Some(f.title.clone())
                }
                _ => None,
            })
            .collect()
    }

    /// Renders the report as a standalone HTML5 document (UTF-8, inline CSS and SVG).
    pub fn to_html(&self) -> String {
        let mut h = String::with_capacity(
            4096 + self
                .sections
                .iter()
                .flat_map(|s| &s.blocks)
                .map(|b| match b {
                    Block::Figure(f) => f.svg.len(),
                    _ => 256,
                })
                .sum::<usize>(),
        );
        let title = escape(&self.title);
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <meta name=\"generator\" content=\"schuler {}\">\n<title>{title}</title>\n\
             <style>{CSS}</style>\n</head>\n<body>\n<h1>{title}</h1>\n",
            env!("CARGO_PKG_VERSION")
        );
        for p in &self.intro {
            let _ = writeln!(h, "<p>{}</p>", escape(p));
        }
        if !self.sections.is_empty() {
            h.push_str("<nav id=\"contents\">\n<h2>Contents</h2>\n<ol>\n");
            for s in &self.sections {
                let _ = writeln!(
                    h,
                    "<li><a href=\"#{}\">{}</a></li>",
                    s.id,
                    escape(&s.heading)
                );
            }
            h.push_str("</ol>\n</nav>\n");
        }
        for (n, s) in self.sections.iter().enumerate() {
            let _ = writeln!(
                h,
                "<section id=\"{}\">\n<h2>{}. {}</h2>",
                s.id,
                n + 1,
                escape(&s.heading)
            );
            for b in &s.blocks {
                render_block(&mut h, b);
            }
            h.push_str("</section>\n");
        }
        let _ = writeln!(
            h,
            "<footer>Generated by schuler {}.</footer>\n</body>\n</html>",
            env!("CARGO_PKG_VERSION")
        );
        h
    }

    /// Writes the HTML document to `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        schuler_io::line_file::write_whole(path, self.to_html())
    }
}

const CSS: &str = "body{font-family:sans-serif;max-width:880px;margin:1.5em auto;padding:0 1em;\
color:#222;line-height:1.45}h1{font-size:1.6em}h2{font-size:1.3em;border-bottom:1px solid #ccc;\
margin-top:1.8em}h3{font-size:1.08em}table{border-collapse:collapse;margin:.8em 0}\
caption{text-align:left;font-weight:bold;padding:.3em 0}th,td{border:1px solid #ccc;\
padding:.25em .6em}th{background:#f3f3f3}td.num{text-align:right;\
font-variant-numeric:tabular-nums}figure{margin:1em 0}figure svg{max-width:100%;height:auto}\
figcaption{font-size:.9em;color:#555}pre{background:#f6f6f6;padding:.6em;overflow-x:auto}\
nav ol{padding-left:1.6em}footer{margin-top:3em;font-size:.85em;color:#777}";

fn render_block(h: &mut String, block: &Block) {
    match block {
        Block::Paragraph(t) => {
            let _ = writeln!(h, "<p>{}</p>", escape(t));
        }
        Block::Subheading(t) => {
            let _ = writeln!(h, "<h3>{}</h3>", escape(t));
        }
        Block::Preformatted(t) => {
            let _ = writeln!(h, "<pre>{}</pre>", escape(t));
        }
        Block::Table(t) => {
            h.push_str("<table>\n");
            if !t.caption.is_empty() {
                let _ = writeln!(h, "<caption>{}</caption>", escape(&t.caption));
            }
            h.push_str("<thead><tr>");
            for c in &t.header {
                let _ = write!(h, "<th>{}</th>", escape(c));
            }
            h.push_str("</tr></thead>\n<tbody>\n");
            let width = t.rows.iter().map(Vec::len).fold(t.header.len(), usize::max);
            for r in &t.rows {
                h.push_str("<tr>");
                for k in 0..width {
                    let c = r.get(k).map_or("", String::as_str);
                    let class = if is_number(c) { " class=\"num\"" } else { "" };
                    let _ = write!(h, "<td{class}>{}</td>", escape(c));
                }
                h.push_str("</tr>\n");
            }
            h.push_str("</tbody>\n</table>\n");
        }
        Block::Figure(f) => {
            // The SVG comes from `Plot::to_svg`, which escapes its own text.
            let _ = write!(
                h,
                "<figure data-x-label=\"{}\" data-y-label=\"{}\">\n{}<figcaption>{}",
                escape(&f.x_label),
                escape(&f.y_label),
                f.svg,
                escape(&f.title)
            );
            if !f.files.is_empty() {
                h.push_str(" — data: ");
                for (k, file) in f.files.iter().enumerate() {
                    if k > 0 {
                        h.push_str(", ");
                    }
                    let e = escape(file);
                    let _ = write!(h, "<a href=\"{e}\">{e}</a>");
                }
            }
            h.push_str("</figcaption>\n</figure>\n");
        }
    }
}

/// Escapes text for HTML and XML content and attribute values: `& < > " '`.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// True when an axis label names a unit in brackets after some text: `"dH [m]"`.
pub fn has_unit(label: &str) -> bool {
    match (label.find('['), label.rfind(']')) {
        (Some(open), Some(close)) => open > 0 && close > open + 1,
        _ => false,
    }
}

/// An anchor id from any text: lowercase ASCII letters, digits, `-` and `_`.
fn slug(id: &str) -> String {
    let s: String = id
        .trim()
        .chars()
        .map(|c| {
            let c = c.to_ascii_lowercase();
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect();
    if s.is_empty() {
        "section".to_owned()
    } else {
        s
    }
}

/// A table cell that reads as a number (right-aligned): `-1.5`, `2e-3`, `12.0 %`.
fn is_number(cell: &str) -> bool {
    let t = cell.trim().trim_end_matches('%').trim_end();
    !t.is_empty() && t.parse::<f64>().is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::LineStyle;

    fn sample() -> Report {
        let mut r = Report::new("R & D <test>");
        r.paragraph("Intro \"quoted\" 'text'.");
        r.section("errors", "Errors & bounds")
            .paragraph("a < b")
            .table(
                Table::new(["kind", "RMS [m]"])
                    .caption("Stats <1>")
                    .row(["<script>", "1.25"])
                    .row(["short"]),
            )
            .plot_with_files(
                &Plot::new("dH & dV", "t [s]", "error [m]").line(
                    "x",
                    &[0.0, 1.0],
                    &[1.0, 2.0],
                    LineStyle::Solid,
                ),
                &["errors.csv", "a&b.svg"],
            );
        r.section("errors", "Again").preformatted("x <y>");
        r.section("Innovations: GNSS pos", "Innovations");
        r
    }

    #[test]
    fn text_is_escaped_everywhere() {
        let html = sample().to_html();
        for raw in ["R & D", "<test>", "<script>", "a < b", "Stats <1>", "x <y>"] {
            assert!(!html.contains(raw), "unescaped {raw:?}");
        }
        for escaped in [
            "<title>R &amp; D &lt;test&gt;</title>",
            "Intro &quot;quoted&quot; &#39;text&#39;.",
            "<td>&lt;script&gt;</td>",
            "<caption>Stats &lt;1&gt;</caption>",
            "<pre>x &lt;y&gt;</pre>",
            "<a href=\"a&amp;b.svg\">a&amp;b.svg</a>",
            "<figcaption>dH &amp; dV",
        ] {
            assert!(html.contains(escaped), "missing {escaped:?}");
        }
    }

    #[test]
    fn structure_has_contents_sections_tables_and_inline_svg() {
        let html = sample().to_html();
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(html.trim_end().ends_with("</html>"));
        // Unique, valid anchors, each linked from the contents in order.
        let ids = ["errors", "errors-2", "innovations--gnss-pos"];
        let mut at = 0;
        for id in ids {
            let link = format!("<li><a href=\"#{id}\">");
            let pos = html[at..].find(&link).expect(&link) + at;
            at = pos;
            assert_eq!(html.matches(&format!("<section id=\"{id}\">")).count(), 1);
        }
        assert_eq!(html.matches("<section ").count(), 3);
        assert_eq!(html.matches("</section>").count(), 3);
        assert!(html.contains("<h2>1. Errors &amp; bounds</h2>"));
        // The short row is padded; numbers are right-aligned, text is not.
        assert!(html.contains("<tr><td>short</td><td></td></tr>"));
        assert!(html.contains("<td class=\"num\">1.25</td>"));
        // One inline SVG inside a figure with its labels; no external resources.
        assert_eq!(html.matches("<svg ").count(), 1);
        assert!(html.contains("<figure data-x-label=\"t [s]\" data-y-label=\"error [m]\">"));
        for external in [
            "<script", "<link", "src=", "url(", "@import", "http://", "https://",
        ] {
            let hits = html.matches(external).count();
            // The only URL allowed is the SVG namespace, which is a name, not a fetch.
            let allowed = if external == "http://" { 1 } else { 0 };
            assert_eq!(hits, allowed, "{external}");
        }
        assert!(html.contains("xmlns=\"http://www.w3.org/2000/svg\""));
    }

    #[test]
    fn plots_without_units_are_listed() {
        let mut r = sample();
        assert!(r.plots_missing_units().is_empty());
        r.section("x", "X")
            .plot(&Plot::new("bad", "time", "error [m]"))
            .plot(&Plot::new("also bad", "t [s]", "[m]"))
            .plot(&Plot::new("good", "NIS [-]", "t [s]"));
        assert_eq!(r.plots_missing_units(), ["bad", "also bad"]);
    }

    #[test]
    fn slugs_and_numbers() {
        assert_eq!(slug(""), "section");
        assert_eq!(slug(" A b_C-9é "), "a-b_c-9-");
        assert!(is_number("-1.5e-3") && is_number("12.0 %") && is_number(" 3 "));
        assert!(!is_number("") && !is_number("n/a") && !is_number("%"));
        assert!(has_unit("dS [m]") && !has_unit("dS") && !has_unit("dS []"));
    }
}
