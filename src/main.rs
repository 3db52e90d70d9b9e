//! The `cloudsketch` binary: the CLI and desktop app natively, the web app on wasm32.

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    cloudsketch::cli::main()
}

#[cfg(target_arch = "wasm32")]
fn main() {
    cloudsketch::web::start();
}
