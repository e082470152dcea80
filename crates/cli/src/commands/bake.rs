//! `mirrorball bake`: the flags become the library's `BakeRequest` (`mirrorball::bake`),
//! planned and baked there; `--for list` prints what each engine gets.

use crate::error::CliError;
use crate::progress::Printer;
use crate::BakeArgs;
use mirrorball::bake::{BakeRequest, Plan};

pub fn run(a: BakeArgs) -> Result<(), CliError> {
    let request = BakeRequest {
        input: a.input,
        engine: a.engine,
        out_dir: a.out_dir,
        size: a.size,
        background_size: a.background_size,
        overwrite: a.overwrite,
        encoding: a.encoding,
        effort: a.effort,
        zstd: a.zstd,
        no_zstd: a.no_zstd,
        mapping: a.mapping,
        samples: a.samples,
        input_plan: crate::commands::input_plan(&a.input_args)?,
    };
    match Plan::new(&request)? {
        Plan::List => {
            print!("{}", mirrorball_bake::list());
            Ok(())
        }
        Plan::Bake(p) => mirrorball::bake::run(*p, &Printer { quiet: a.quiet }),
    }
}
