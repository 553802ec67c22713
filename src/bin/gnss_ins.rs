//! `gnss_ins`: the offline tools — simulate a scenario into a bag, replay a bag through
//! the engine, compare filter variants, and the demo that does all of it.

use std::process::ExitCode;

use clap::Parser;

use adaptive_gnss_ins::tools::cli;

#[derive(Parser)]
#[command(
    name = "gnss_ins",
    version,
    about = "Adaptive tightly-coupled GNSS/INS: offline tools"
)]
struct Args {
    #[command(subcommand)]
    command: cli::Command,
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let args = Args::parse();
    match cli::run(args.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gnss_ins: {e}");
            ExitCode::FAILURE
        }
    }
}
