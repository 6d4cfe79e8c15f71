//! `tandem`: thin main over [`tandem_cli::run`].

fn main() -> std::process::ExitCode {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    tandem_cli::run(args, &mut std::io::stdout(), &mut std::io::stderr())
}
