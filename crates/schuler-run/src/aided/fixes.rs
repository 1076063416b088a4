//! The GNSS fixes of a run, held as [`Spilled`] records (bounded memory, the rest on
//! disk) with what the report and the clock check need of all of them: their count,
//! first and last, and the gaps between them ([`super::report::gnss_gaps`]). A
//! 10-hour log's 36,000 fixes thus cost the memory of a 1-hour one's once the run
//! starts (issue 22).

use super::spilled::{Record, Spilled};
use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;

impl Record for GnssFix {
    /// `t, lat, lon, h [rad, m], pos_std (3), velocity flag, vel (3), vel_std (3)`.
    const WIDTH: usize = 14;

    fn encode(&self, out: &mut [f64]) {
        let p = &self.pos;
        out[..7].copy_from_slice(&[
            self.t,
            p.lat,
            p.lon,
            p.h,
            self.pos_std.x,
            self.pos_std.y,
            self.pos_std.z,
        ]);
        let (flag, (v, s)) = match self.vel {
            Some(vel) => (1.0, vel),
            None => (0.0, (Vector3::zeros(), Vector3::zeros())),
        };
        out[7] = flag;
        out[8..11].copy_from_slice(v.as_slice());
        out[11..14].copy_from_slice(s.as_slice());
    }

    fn decode(r: &[f64]) -> Self {
        let v = |o: usize| Vector3::new(r[o], r[o + 1], r[o + 2]);
        GnssFix {
            t: r[0],
            pos: Geodetic {
                lat: r[1],
                lon: r[2],
                h: r[3],
            },
            pos_std: v(4),
            vel: (r[7] != 0.0).then(|| (v(8), v(11))),
        }
    }
}

/// GNSS fixes in time order (module doc).
#[derive(Debug, Clone, Default)]
pub struct Fixes {
    store: Spilled<GnssFix>,
    first: Option<GnssFix>,
    last: Option<GnssFix>,
    gaps: Vec<(f64, f64)>,
}

impl From<Vec<GnssFix>> for Fixes {
    /// The fixes pushed one by one, then closed: the same path as a streamed log.
    fn from(fixes: Vec<GnssFix>) -> Self {
        let mut store = Self::default();
        for f in &fixes {
            store.push(f);
        }
        store.closed()
    }
}

impl Fixes {
    /// Adds `fix`, later than every fix before it.
    pub fn push(&mut self, fix: &GnssFix) {
        self.store.push(fix);
        self.first.get_or_insert(*fix);
        self.last = Some(*fix);
    }

    /// The store with its gaps, once every fix is pushed (they need the median
    /// spacing of all of them: 8 bytes a fix, for the time of this call).
    pub fn closed(mut self) -> Self {
        let times: Vec<f64> = self.iter().map(|f| f.t).collect();
        self.gaps = super::report::gaps_of_times(&times);
        self
    }

    /// How many.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.store.is_empty()
    }

    /// The first.
    pub fn first(&self) -> Option<GnssFix> {
        self.first
    }

    /// The last.
    pub fn last(&self) -> Option<GnssFix> {
        self.last
    }

    /// The gaps between them ([`super::report::gnss_gaps`]).
    pub fn gaps(&self) -> &[(f64, f64)] {
        &self.gaps
    }

    /// Every fix, in time order (read back from the store; a storage failure ends
    /// the iteration and is reported by [`Fixes::status`]).
    pub fn iter(&self) -> impl Iterator<Item = GnssFix> + '_ {
        self.store.iter()
    }

    /// Every fix in memory (for the start in motion, which searches them).
    pub fn to_vec(&self) -> anyhow::Result<Vec<GnssFix>> {
        let all = self.iter().collect();
        self.status()?;
        Ok(all)
    }

    /// Bytes of fixes held in memory (the rest is on disk).
    pub fn in_memory(&self) -> usize {
        self.store.in_memory()
    }

    /// An error if the store failed (a full temporary disk).
    pub fn status(&self) -> anyhow::Result<()> {
        self.store.status()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fixes come back bit for bit, with and without a velocity; the count, ends and
    /// gaps are those of the whole list, and the memory held stays under the budget.
    #[test]
    fn fixes_come_back_with_their_summary() {
        let fix = |k: usize| GnssFix {
            t: if k < 500 { k as f64 } else { k as f64 + 60.0 },
            pos: Geodetic::from_degrees(45.0 + 1e-9 * k as f64, 7.0, 300.0 - 0.1 * k as f64),
            pos_std: Vector3::new(0.5, 0.6, 1.0 + k as f64),
            vel: k
                .is_multiple_of(3)
                .then(|| (Vector3::new(1.0, -2.0, k as f64), Vector3::repeat(0.1))),
        };
        let all: Vec<GnssFix> = (0..20_000).map(fix).collect();
        let fixes = Fixes::from(all.clone());
        assert_eq!(fixes.len(), all.len());
        assert_eq!(
            (fixes.first(), fixes.last()),
            (all.first().copied(), all.last().copied())
        );
        assert_eq!(fixes.gaps(), [(499.0, 560.0)]);
        assert!(fixes.store.in_memory() <= super::super::spilled::BUDGET);
        assert_eq!(fixes.to_vec().expect("read back"), all);
    }
}
