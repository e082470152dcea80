//! Named choices on the command line: the help lists each flag's values from the table of
//! the [`Choice`] that owns them, the one the plan parses the flag's text with.

use clap::builder::{PossibleValue, StringValueParser, TypedValueParser};
use mirrorball_core::Choice;

/// A value parser whose help (and shell completion) lists the canonical names of a
/// [`Choice`]'s values, aliases hidden. The text itself passes through unchanged: the plan
/// parses it with the same table, so that a bad value is reported, in the command's own
/// words, with the other checks of the request.
#[derive(Clone)]
pub struct Names(Vec<&'static [&'static str]>);

/// [`Names`] of every value of `T`.
pub fn names<T: Choice>() -> Names {
    Names(T::NAMES.iter().map(|(_, n)| *n).collect())
}

/// [`Names`] of the values of `T` in `offered` (a command that offers only some).
pub fn names_of<T: Choice>(offered: &[T]) -> Names {
    Names(
        T::NAMES
            .iter()
            .filter(|(v, _)| offered.contains(v))
            .map(|(_, n)| *n)
            .collect(),
    )
}

pub use mirrorball::spec::parse_flag;

impl TypedValueParser for Names {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        StringValueParser::new().parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.0.iter().map(|n| {
            PossibleValue::new(n[0]).aliases(n[1..].iter().copied())
        })))
    }
}
