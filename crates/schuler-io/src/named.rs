//! Closed sets of values that files, configurations and flags name by a word
//! (`--gyro-unit deg/s`, `gnss_format = "nmea"`): each value with its name and a
//! one-line description, listed once so that every front end offers and reads the same
//! names.

/// A type whose values are all listed with their names and descriptions.
pub trait Named: Copy + PartialEq + 'static {
    /// Every value with its name and a one-line description, in the order shown to
    /// users.
    const VALUES: &'static [(Self, &'static str, &'static str)];

    /// The value's name (each value is listed in [`Named::VALUES`], a test of each
    /// type checks it).
    fn name(self) -> &'static str {
        Self::VALUES
            .iter()
            .find(|(v, _, _)| *v == self)
            .map_or("", |(_, n, _)| n)
    }

    /// The value of a name, if it is one.
    fn from_name(name: &str) -> Option<Self> {
        Self::VALUES
            .iter()
            .find(|(_, n, _)| *n == name)
            .map(|(v, _, _)| *v)
    }
}

/// Checks that `T` lists `all` (every value of the type) once each, under the names
/// serde reads: the one list behind flags and configuration keys agrees with the
/// derive.
#[cfg(test)]
pub(crate) fn check_listing<T>(all: &[T])
where
    T: Named + std::fmt::Debug + serde::de::DeserializeOwned,
{
    assert_eq!(T::VALUES.len(), all.len(), "one entry per value");
    for v in all {
        let name = v.name();
        assert!(!name.is_empty(), "{v:?} is listed");
        assert_eq!(T::from_name(name), Some(*v));
        let de: serde::de::value::StrDeserializer<'_, serde::de::value::Error> =
            serde::de::IntoDeserializer::into_deserializer(name);
        let read = T::deserialize(de).unwrap_or_else(|e| panic!("serde reads {name}: {e}"));
        assert_eq!(read, *v, "serde's name of {v:?}");
    }
}
