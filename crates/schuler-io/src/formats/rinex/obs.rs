//! RINEX observation files: epochs of pseudorange, carrier phase, Doppler and C/N0 (to be written).
