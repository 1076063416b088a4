//! Raw GNSS: satellites, their broadcast orbits and clocks, the signal's path through
//! the atmosphere, and positions from pseudoranges.
//!
//! Times are GPS time (GPST) as a week number and seconds of week unless a module says
//! otherwise; positions are ECEF (WGS84 for GPS, the systems' own realisations of ITRF
//! otherwise, which agree at the centimetre level).

mod sat;

pub use sat::{Sat, System};
