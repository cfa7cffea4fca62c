//! Cross-crate tests of Spectrace. The library is empty; the tests live in `tests/cross_crate.rs`
//! (one integration-test binary, so the workspace links one test executable for all of them).
