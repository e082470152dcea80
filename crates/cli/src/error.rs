//! The CLI's error is the library's [`mirrorball::Error`]: a message for people and whose
//! fault it is, which picks the exit status ([`exit_code`]).

pub use mirrorball::Error as CliError;
use mirrorball_core::Fault;

/// The exit status: 2 when the request cannot be met, 1 when the input or the system
/// failed.
pub fn exit_code(e: &CliError) -> u8 {
    match e.fault {
        Fault::Request => 2,
        Fault::Input | Fault::System => 1,
    }
}
