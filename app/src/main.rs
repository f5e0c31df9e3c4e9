use std::process::ExitCode;

fn main() -> ExitCode {
    anthesis_app::cli::main()
}
