//! `mirrorball info`: what a file holds (the library's `info::describe`; a video's 360°
//! metadata through `tag`), printed for people or as JSON.

use crate::error::CliError;
use crate::InfoArgs;

pub fn run(a: InfoArgs) -> Result<(), CliError> {
    if super::tag::is_movie(&a.input) {
        return super::tag::info(&a.input, a.json);
    }
    let input = crate::commands::input_plan(&a.input_args)?;
    let info = mirrorball::info::describe(&a.input, &input)?;
    match a.json {
        true => println!(
            "{}",
            serde_json::to_string_pretty(&info.json).expect("serialisable")
        ),
        false => print!("{}", info.text),
    }
    Ok(())
}
