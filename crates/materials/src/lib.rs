//! Materials of Spectrace (being written).
