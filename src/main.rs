//! The `ballpit` binary: on Linux with glibc, start again with the heap on huge pages (see
//! `ballpit::huge_pages`); then parse the command line and run it. Everything else is in the
//! library.

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    // First, while nothing has run: on Linux with glibc this starts the binary again with its
    // heap on huge pages, and returns only where it does not (see `huge_pages`).
    ballpit::huge_pages::rerun_with_huge_pages();
    ballpit::cli::Cli::parse().run()
}
