//! Nothing here: the tests are the crate (`tests/bevy/tests`).
