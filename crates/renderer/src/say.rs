//! Printing to the terminal that never panics. `println!` and `eprintln!` panic when their stream
//! is closed (`spectrace render scene.json | head -1` closes stdout after one line); these write a
//! line and drop the error instead, since nobody is left to read it, and the render, its files
//! and its exit code are unaffected.

/// A line on stdout, like `println!`, ignoring a closed or failing stream.
macro_rules! say {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = writeln!(::std::io::stdout().lock(), $($arg)*);
    }};
}

/// A line on stderr, like `eprintln!`, ignoring a closed or failing stream.
macro_rules! tell {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = writeln!(::std::io::stderr().lock(), $($arg)*);
    }};
}

pub(crate) use {say, tell};
