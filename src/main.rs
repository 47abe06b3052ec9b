//! The `magsep` command-line tool. Exit codes: 0 ok, 2 bad input, 1 runtime failure.

/// mimalloc keeps freed pages for reuse: glibc's malloc returned the heap top to the system
/// after each step of runs whose per-step buffers are freed together, and faulted it back in
/// on the next (see `Cargo.toml`).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(magsep::cli::main());
}
