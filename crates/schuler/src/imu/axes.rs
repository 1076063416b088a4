//! Where a sensor's axes point on its vehicle, written as three letters, and the
//! rotation that carries the sensor's measurements into the vehicle's
//! front-right-down (FRD) axes.
//!
//! `"RBD"` says: the sensor's x axis points to the vehicle's right, its y axis to the
//! back, its z axis down. The letters are F (front), B (back), R (right), L (left), U
//! (up) and D (down); `"FRD"` is the identity, `"FLU"` the body frame of ROS REP 103.
//! The three axes must be mutually perpendicular and right-handed (x × y = z): a
//! left-handed set such as `"FRU"` would mirror every rotation, so it is refused, as
//! are directions on the Earth (N, E, S, W), which are not axes of a vehicle.

use std::fmt;
use std::str::FromStr;

use nalgebra::{Matrix3, Vector3};

/// A direction on a vehicle, one of the six FRD half-axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Front (+x of FRD).
    Front,
    /// Back (−x of FRD).
    Back,
    /// Right (+y of FRD).
    Right,
    /// Left (−y of FRD).
    Left,
    /// Up (−z of FRD).
    Up,
    /// Down (+z of FRD).
    Down,
}

impl Direction {
    /// The direction of a letter (`F`, `B`, `R`, `L`, `U`, `D`, either case).
    pub fn from_letter(c: char) -> Option<Self> {
        match c.to_ascii_uppercase() {
            'F' => Some(Self::Front),
            'B' => Some(Self::Back),
            'R' => Some(Self::Right),
            'L' => Some(Self::Left),
            'U' => Some(Self::Up),
            'D' => Some(Self::Down),
            _ => None,
        }
    }

    /// The direction's letter (upper case).
    pub fn letter(self) -> char {
        match self {
            Self::Front => 'F',
            Self::Back => 'B',
            Self::Right => 'R',
            Self::Left => 'L',
            Self::Up => 'U',
            Self::Down => 'D',
        }
    }

    /// The direction as a unit vector in FRD components.
    pub fn unit_frd(self) -> Vector3<f64> {
        match self {
            Self::Front => Vector3::new(1.0, 0.0, 0.0),
            Self::Back => Vector3::new(-1.0, 0.0, 0.0),
            Self::Right => Vector3::new(0.0, 1.0, 0.0),
            Self::Left => Vector3::new(0.0, -1.0, 0.0),
            Self::Up => Vector3::new(0.0, 0.0, -1.0),
            Self::Down => Vector3::new(0.0, 0.0, 1.0),
        }
    }

    /// The FRD axis (0 = x, 1 = y, 2 = z) the direction lies on.
    fn axis(self) -> usize {
        match self {
            Self::Front | Self::Back => 0,
            Self::Right | Self::Left => 1,
            Self::Up | Self::Down => 2,
        }
    }
}

/// Why a set of axis letters was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum AxesError {
    /// Not three letters.
    #[error(
        "{0:?}: expected three letters, one per sensor axis x, y, z, each one of F, B, R, L, U, D (e.g. FRD, RBD, FLU)"
    )]
    Length(String),
    /// A letter that names no direction on a vehicle.
    #[error(
        "{text:?}: {letter:?} (axis {axis}) is not a direction on a vehicle; use F, B, R, L, U, D (front, back, right, left, up, down)"
    )]
    NotADirection {
        /// The letters as given.
        text: String,
        /// The offending letter.
        letter: char,
        /// The sensor axis it was given for (`x`, `y` or `z`).
        axis: char,
    },
    /// N, E, S or W: a direction on the Earth, not on the vehicle.
    #[error(
        "{text:?}: {letter:?} is a direction on the Earth; these letters say where the sensor's axes point on the vehicle (F, B, R, L, U, D). A sensor whose data come in ENU or NED axes has already been turned into a navigation frame; a ROS body frame (REP 103: x forward, y left, z up) is FLU"
    )]
    EarthDirection {
        /// The letters as given.
        text: String,
        /// The offending letter.
        letter: char,
    },
    /// Two axes along the same vehicle axis.
    #[error(
        "{text:?}: axes {first} and {second} both lie along the vehicle's {along} axis; the three sensor axes must be perpendicular (one of F/B, one of R/L, one of U/D)"
    )]
    Parallel {
        /// The letters as given.
        text: String,
        /// The first sensor axis (`x`, `y`, `z`).
        first: char,
        /// The second sensor axis.
        second: char,
        /// The vehicle axis both lie on (`front-back`, ...).
        along: &'static str,
    },
    /// Perpendicular axes that form a left-handed frame.
    #[error(
        "{text:?} is a left-handed frame (x × y = −z): no rotation turns a right-handed sensor into it, so one axis is named the wrong way; flipping any single letter gives a right-handed set, e.g. {suggestion}"
    )]
    LeftHanded {
        /// The letters as given.
        text: String,
        /// The same letters with z flipped.
        suggestion: String,
    },
}

/// Where a sensor's x, y and z axes point on the vehicle; always a right-handed frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SensorAxes {
    axes: [Direction; 3],
}

impl SensorAxes {
    /// The sensor's axes are the vehicle's FRD axes (the identity).
    pub const FRD: SensorAxes = SensorAxes {
        axes: [Direction::Front, Direction::Right, Direction::Down],
    };

    /// The axes `[x, y, z]` point along `axes`; refused unless perpendicular and
    /// right-handed (`text` names them in errors).
    pub fn new(axes: [Direction; 3]) -> Result<Self, AxesError> {
        let text: String = axes.iter().map(|d| d.letter()).collect();
        Self::checked(axes, &text)
    }

    fn checked(axes: [Direction; 3], text: &str) -> Result<Self, AxesError> {
        const NAMES: [char; 3] = ['x', 'y', 'z'];
        const ALONG: [&str; 3] = ["front-back", "right-left", "up-down"];
        for i in 0..3 {
            for j in i + 1..3 {
                if axes[i].axis() == axes[j].axis() {
                    return Err(AxesError::Parallel {
                        text: text.to_owned(),
                        first: NAMES[i],
                        second: NAMES[j],
                        along: ALONG[axes[i].axis()],
                    });
                }
            }
        }
        let [x, y, z] = axes.map(Direction::unit_frd);
        if x.cross(&y).dot(&z) < 0.0 {
            let flipped = match axes[2] {
                Direction::Front => Direction::Back,
                Direction::Back => Direction::Front,
                Direction::Right => Direction::Left,
                Direction::Left => Direction::Right,
                Direction::Up => Direction::Down,
                Direction::Down => Direction::Up,
            };
            let suggestion = [axes[0], axes[1], flipped]
                .iter()
                .map(|d| d.letter())
                .collect();
            return Err(AxesError::LeftHanded {
                text: text.to_owned(),
                suggestion,
            });
        }
        Ok(Self { axes })
    }

    /// The directions of the sensor's x, y, z axes.
    pub fn directions(&self) -> [Direction; 3] {
        self.axes
    }

    /// Whether the sensor axes are the vehicle's FRD axes.
    pub fn is_frd(&self) -> bool {
        *self == Self::FRD
    }

    /// `c_vs`: the DCM from sensor to vehicle FRD axes, `v_frd = c_vs * v_sensor`; its
    /// columns are the sensor axes in FRD components, its entries 0 and ±1 exactly.
    pub fn c_vs(&self) -> Matrix3<f64> {
        let [x, y, z] = self.axes.map(Direction::unit_frd);
        Matrix3::from_columns(&[x, y, z])
    }
}

impl FromStr for SensorAxes {
    type Err = AxesError;

    /// Three letters, one per sensor axis (`"RBD"`; blanks around them ignored).
    fn from_str(s: &str) -> Result<Self, AxesError> {
        let text = s.trim();
        let letters: Vec<char> = text.chars().collect();
        let [x, y, z] = letters[..] else {
            return Err(AxesError::Length(text.to_owned()));
        };
        let mut axes = [Direction::Front; 3];
        for ((slot, letter), axis) in axes.iter_mut().zip([x, y, z]).zip(['x', 'y', 'z']) {
            *slot = match Direction::from_letter(letter) {
                Some(d) => d,
                None if matches!(letter.to_ascii_uppercase(), 'N' | 'E' | 'S' | 'W') => {
                    return Err(AxesError::EarthDirection {
                        text: text.to_owned(),
                        letter,
                    });
                }
                None => {
                    return Err(AxesError::NotADirection {
                        text: text.to_owned(),
                        letter,
                        axis,
                    });
                }
            };
        }
        Self::checked(axes, text)
    }
}

impl fmt::Display for SensorAxes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for d in self.axes {
            write!(f, "{}", d.letter())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every signed permutation of the FRD axes: 6 orders × 8 sign patterns.
    fn signed_permutations() -> Vec<[Direction; 3]> {
        use Direction::*;
        let pairs = [[Front, Back], [Right, Left], [Down, Up]];
        let orders = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let mut out = Vec::new();
        for order in orders {
            for signs in 0..8 {
                out.push([0, 1, 2].map(|i| pairs[order[i]][(signs >> i) & 1]));
            }
        }
        out
    }

    #[test]
    fn right_handed_triads_have_det_one_the_others_are_refused() {
        let all = signed_permutations();
        assert_eq!(all.len(), 48);
        let mut accepted = 0;
        for axes in all {
            let text: String = axes.iter().map(|d| d.letter()).collect();
            let [x, y, z] = axes.map(Direction::unit_frd);
            let det = Matrix3::from_columns(&[x, y, z]).determinant();
            match text.parse::<SensorAxes>() {
                Ok(s) => {
                    accepted += 1;
                    assert_eq!(det, 1.0, "{text}");
                    let c = s.c_vs();
                    assert_eq!(c.determinant(), 1.0, "{text}");
                    assert_eq!(c.transpose() * c, Matrix3::identity(), "{text}");
                    assert_eq!(s.to_string(), text);
                }
                Err(e) => {
                    assert_eq!(det, -1.0, "{text}");
                    assert!(matches!(e, AxesError::LeftHanded { .. }), "{text}: {e}");
                    // The suggested set is right-handed.
                    let AxesError::LeftHanded { suggestion, .. } = e else {
                        unreachable!("matched above")
                    };
                    assert!(suggestion.parse::<SensorAxes>().is_ok(), "{suggestion}");
                }
            }
        }
        assert_eq!(accepted, 24, "the rotation group of the cube");
    }

    #[test]
    fn frd_is_the_identity() {
        let s: SensorAxes = "frd".parse().expect("FRD");
        assert!(s.is_frd());
        assert_eq!(s.c_vs(), Matrix3::identity());
    }

    /// ROS REP 103 body axes: x forward, y left, z up.
    #[test]
    fn flu_maps_ros_axes_to_frd() {
        let c = "FLU".parse::<SensorAxes>().expect("FLU").c_vs();
        assert_eq!(c, Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)));
        // Gravity's reaction read by a level ROS IMU (+g along its z, up) is FRD −g on z.
        assert_eq!(
            c * Vector3::new(0.0, 0.0, 9.8),
            Vector3::new(0.0, 0.0, -9.8)
        );
    }

    /// The rover of the issue: the IMU's x points right, y back, z down.
    #[test]
    fn rbd_maps_as_the_rover() {
        let c = "RBD".parse::<SensorAxes>().expect("RBD").c_vs();
        // Driving forward, the IMU feels the push on its −y axis.
        assert_eq!(
            c * Vector3::new(0.0, -2.0, 0.0),
            Vector3::new(2.0, 0.0, 0.0)
        );
        // A turn to the right (yaw rate about down) is about the IMU's z, unchanged.
        assert_eq!(c * Vector3::new(0.0, 0.0, 0.1), Vector3::new(0.0, 0.0, 0.1));
        // A right-side push (+y FRD) is on the IMU's x.
        assert_eq!(c * Vector3::new(1.5, 0.0, 0.0), Vector3::new(0.0, 1.5, 0.0));
        assert_eq!(
            c,
            Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        );
    }

    #[test]
    fn bad_letters_are_refused_with_a_reason() {
        let err = |s: &str| s.parse::<SensorAxes>().expect_err(s);
        assert!(matches!(err("FRU"), AxesError::LeftHanded { .. }));
        assert!(err("FRU").to_string().contains("FRD"), "{}", err("FRU"));
        assert!(matches!(
            err("FFD"),
            AxesError::Parallel {
                first: 'x',
                second: 'y',
                ..
            }
        ));
        assert!(matches!(err("ENU"), AxesError::EarthDirection { .. }));
        assert!(err("NED").to_string().contains("REP 103"));
        assert!(matches!(
            err("FXD"),
            AxesError::NotADirection {
                letter: 'X',
                axis: 'y',
                ..
            }
        ));
        assert!(matches!(err("FR"), AxesError::Length(_)));
        assert!(matches!(err("FRDU"), AxesError::Length(_)));
        assert!(matches!(
            SensorAxes::new([Direction::Up, Direction::Up, Direction::Front]),
            Err(AxesError::Parallel { .. })
        ));
    }
}
