//! The `magsep` command-line tool. Exit codes: 0 ok, 2 bad input, 1 runtime failure.

fn main() {
    std::process::exit(magsep::cli::main());
}
