//! Raw GNSS: satellites, their broadcast orbits and clocks, the signal's path through
//! the atmosphere, and positions from pseudoranges.
//!
//! Times are GPS time (GPST) as a week number and seconds of week ([`GpsTime`]) unless
//! a module says otherwise; positions are ECEF (WGS84 for GPS, the systems' own
//! realisations of ITRF otherwise, which agree at the centimetre level).
//!
//! A satellite's state for a pseudorange: read the navigation file into an
//! [`EphemerisStore`], [`EphemerisStore::select`] the ephemeris for the satellite at
//! the receive time, then [`Ephemeris::state_at_reception`] (transmission time, orbit,
//! clock with the relativistic term, Earth rotation during the travel), and correct the
//! clock for the band's [`Ephemeris::group_delay`].
//!
//! A position from raw measurements: convert a source's epoch into a [`RawEpoch`]
//! ([`raw`]), then [`spp::solve`] it (single-point position, clocks, Doppler velocity,
//! fault detection and exclusion).

pub mod atmosphere;
mod dop;
mod ephemeris;
mod orbit;
pub mod ranging;
pub mod raw;
mod sat;
pub mod spp;
mod store;
pub mod time;
mod transmit;

pub use dop::Dop;
pub use ephemeris::{
    Band, C, DEFAULT_VALIDITY_S, EARLY_S, Ephemeris, GALILEO_VALIDITY_S, ICD_PI, Kepler,
    NavMessage, SystemConstants,
};
pub use orbit::{OrbitPoint, SatState, eccentric_anomaly};
pub use ranging::{Predicted, RangeEpoch, RangeModel, SatRange};
pub use raw::{PhaseLock, RawEpoch, RawMeasurement, Signal};
pub use sat::{Sat, System};
pub use spp::{SppConfig, SppError, SppSolution};
pub use store::EphemerisStore;
pub use time::GpsTime;
