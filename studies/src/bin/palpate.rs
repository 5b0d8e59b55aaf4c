//! The `palpate` binary: parses the command line and reports errors as
//! readable messages with their causes (never a panic on user input).

use clap::Parser;
use palpate_studies::cli::{dispatch, join_negative_values, Cli};

fn main() -> std::process::ExitCode {
    let cli = Cli::parse_from(join_negative_values(std::env::args_os()));
    match dispatch(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            for cause in e.chain().skip(1) {
                eprintln!("  caused by: {cause}");
            }
            std::process::ExitCode::from(2)
        }
    }
}
