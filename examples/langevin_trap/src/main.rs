//! The `langevin-trap` binary: the magsep command line (`run`, `validate`, `info`, `replay`,
//! ...) with the built-in pipelines plus `langevin_trap`.

fn main() {
    std::process::exit(magsep::cli::main_with(
        magsep::cli::Extensions::default().pipeline(langevin_trap::LangevinTrapPipeline),
    ))
}
