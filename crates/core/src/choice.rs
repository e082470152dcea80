//! Named choices: fieldless enums spelt by one table of names.
//!
//! Every value a user picks by name (a projection kind, a layout, a lens, a filter, an
//! indexing mode, …) is a type in the crate that owns the concept, implementing [`Choice`]
//! with one table: each value's names, canonical name first, then its aliases. Parsing
//! ([`Choice::from_name`], and `FromStr` through [`choice_traits!`]), printing (`Display`,
//! [`Choice::name`]), the lists in error messages ([`UnknownName`]) and the CLI's help
//! (its value parsers read [`Choice::NAMES`]) are all read from that table, so they
//! cannot disagree.
//!
//! ```
//! use mirrorball_core::{Choice, Layout};
//! assert_eq!(Layout::from_name("Horizontal_Cross"), Some(Layout::HorizontalCross));
//! assert_eq!(Layout::HorizontalCross.name(), "hcross");
//! assert_eq!("hcross".parse::<Layout>().unwrap().to_string(), "hcross");
//! ```

use std::fmt;

/// A value picked by name from a fixed set.
pub trait Choice: Copy + PartialEq + 'static {
    /// Every value with its names: `(value, [canonical, aliases…])`, in the order values are
    /// listed to people. Names are lower-case and use `-` between words.
    const NAMES: &'static [(Self, &'static [&'static str])];

    /// The canonical name (the first of the value's names).
    fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(v, _)| *v == self)
            .map(|(_, names)| names[0])
            .expect("every value of a Choice is in its table")
    }

    /// The value any of whose names is `s`, ignoring case, surrounding space and the
    /// difference between `_` and `-`.
    fn from_name(s: &str) -> Option<Self> {
        let key = s.trim().to_ascii_lowercase().replace('_', "-");
        Self::NAMES
            .iter()
            .find(|(_, names)| names.contains(&key.as_str()))
            .map(|(v, _)| *v)
    }

    /// Every value, in table order.
    fn all() -> impl Iterator<Item = Self> {
        Self::NAMES.iter().map(|(v, _)| *v)
    }

    /// [`Choice::from_name`], or an error listing the canonical names.
    fn parse_name(s: &str) -> Result<Self, UnknownName> {
        Self::from_name(s).ok_or_else(|| UnknownName::new::<Self>(s))
    }
}

/// A name that is none of a [`Choice`]'s: what was given, and the canonical names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownName {
    /// What was given, as given.
    pub given: String,
    /// The canonical names, in table order.
    pub known: Vec<&'static str>,
}

impl UnknownName {
    /// `given` is not a name of `T`.
    pub fn new<T: Choice>(given: &str) -> UnknownName {
        UnknownName::among(given, T::all().map(T::name))
    }

    /// `given` is none of `known` (a subset of a choice's values that a caller offers).
    pub fn among(given: &str, known: impl IntoIterator<Item = &'static str>) -> UnknownName {
        UnknownName {
            given: given.to_string(),
            known: known.into_iter().collect(),
        }
    }

    /// The known names as prose: `a, b or c`.
    pub fn one_of(&self) -> String {
        match self.known.split_last() {
            None => String::new(),
            Some((last, [])) => last.to_string(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        }
    }

    /// The known names as a list: `a, b, c`.
    pub fn list(&self) -> String {
        self.known.join(", ")
    }
}

impl fmt::Display for UnknownName {
    /// `'x' is not a, b or c`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "'{}' is not {}", self.given, self.one_of())
    }
}

impl std::error::Error for UnknownName {}

/// Implements `Display` (the canonical name) and `FromStr` (any name, error
/// [`UnknownName`]) for a [`Choice`].
#[macro_export]
macro_rules! choice_traits {
    ($t:ty) => {
        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::Choice::name(*self))
            }
        }
        impl ::std::str::FromStr for $t {
            type Err = $crate::UnknownName;
            fn from_str(s: &str) -> ::std::result::Result<Self, Self::Err> {
                <$t as $crate::Choice>::parse_name(s)
            }
        }
    };
}

/// `n` and the noun for people, singular for one: `1 level`, `0 levels`, `6 faces`. Every
/// count a message or a summary line prints goes through it.
///
/// ```
/// use mirrorball_core::count;
/// assert_eq!(count(1, "level"), "1 level");
/// assert_eq!(count(9, "level"), "9 levels");
/// assert_eq!(count(0, "file"), "0 files");
/// ```
pub fn count(n: u64, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Abc {
        A,
        B,
        C,
    }
    impl Choice for Abc {
        const NAMES: &'static [(Self, &'static [&'static str])] = &[
            (Abc::A, &["a", "alpha"]),
            (Abc::B, &["b"]),
            (Abc::C, &["c-c"]),
        ];
    }
    choice_traits!(Abc);

    #[test]
    fn names_aliases_and_messages_come_from_the_table() {
        assert_eq!(Abc::from_name(" ALPHA "), Some(Abc::A));
        assert_eq!(Abc::from_name("c_c"), Some(Abc::C));
        assert_eq!(Abc::C.name(), "c-c");
        assert_eq!(Abc::B.to_string(), "b");
        assert_eq!("alpha".parse::<Abc>(), Ok(Abc::A));
        let e = "d".parse::<Abc>().unwrap_err();
        assert_eq!(e.to_string(), "'d' is not a, b or c-c");
        assert_eq!(e.list(), "a, b, c-c");
        for v in Abc::all() {
            assert_eq!(v.name().parse::<Abc>(), Ok(v));
        }
    }
}
