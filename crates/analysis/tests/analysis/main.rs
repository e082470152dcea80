//! mirrorball-analysis integration tests: measured values against independent closed forms.
mod closed_forms;
mod indexing;
mod profiles;
mod report;
mod util;
