//! One module per subcommand.
pub mod analyze;
pub mod bake;
pub mod compare;
pub mod convert;
pub mod demo;
pub mod frames;
pub mod info;
pub mod prefilter;
pub mod render;
pub mod studio;
pub mod tag;
pub mod views;

use crate::error::CliError;
use crate::spec::{bad, ProjSpec};
use crate::InputArgs;

pub use mirrorball::load::InputPlan;

/// The input flags as the library's [`InputPlan`].
pub fn input_plan(a: &InputArgs) -> Result<InputPlan, CliError> {
    let from = a
        .from
        .as_deref()
        .map(ProjSpec::parse)
        .transpose()
        .map_err(|e| bad("--from", e))?;
    let layout = parse_layout("--in-layout", a.in_layout.as_deref())?;
    Ok(InputPlan {
        from,
        layout,
        keep_invalid: a.keep_invalid,
    })
}

pub use mirrorball::spec::parse_layout;
