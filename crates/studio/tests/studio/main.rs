//! The studio's server, through real requests to a running server.

mod faults;
mod host;
mod security;
mod serving;
