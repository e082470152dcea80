//! `mirrorball demo`: the flags become the library's `DemoRequest` (`mirrorball::demo`).

use crate::error::CliError;
use crate::progress::Printer;
use crate::DemoArgs;
use mirrorball::demo::DemoRequest;

pub fn run(a: DemoArgs) -> Result<(), CliError> {
    let request = DemoRequest {
        out: a.out,
        size: a.size,
        exposure: a.exposure,
    };
    mirrorball::demo::run(&request, &Printer { quiet: false })
}
