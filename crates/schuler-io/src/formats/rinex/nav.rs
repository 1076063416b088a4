//! RINEX navigation files: broadcast ephemerides (to be written).
