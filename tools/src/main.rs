//! `dnurbs`: real-time 5-axis double-NURBS interpolation.
//!
//! Parse the command line ([`dnurbs_tools::cli`]), run the subcommand
//! ([`dnurbs_tools::commands`]) and exit with the code of its outcome or error, one table
//! for every subcommand ([`dnurbs_tools::exit`]).

use clap::Parser;
use dnurbs_tools::cli::Cli;
use dnurbs_tools::{commands, exit};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match commands::dispatch(cli.command) {
        Ok(outcome) => ExitCode::from(outcome.code()),
        Err(e) => {
            eprintln!("dnurbs: {e:#}");
            ExitCode::from(exit::code_of(&e))
        }
    }
}
