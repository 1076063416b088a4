//! Reports of the schuler toolkit: self-contained HTML pages ([`html`]) with SVG line
//! plots ([`plot`]) that render a finished run's results.
//!
//! A report is drawn after the run, from what it computed: nothing here reads a log,
//! runs a filter or parses a flag (see ARCHITECTURE.md).

pub mod html;
pub mod plot;
