//! The `palpate` binary: parses the command line and reports errors as
//! readable messages with their causes (never a panic on user input).

use clap::Parser;
use palpate_studies::cli::{dispatch, Cli};

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
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
