//! The documentation states what the code does: numbers and behaviours that the READMEs quote
//! are checked against the constants and defaults they describe.

use magsep::plugins::record::{FrameBuffering, RATIO_FREE_BYTES};

const RECORDINGS_README: &str = include_str!("../../recordings/README.md");
const README: &str = include_str!("../../README.md");

/// Frames share zstd chunks (1 s or 1 MiB by default): `recordings/README.md` must not claim
/// one chunk per frame, and quotes the buffering's limits and the reader's ratio exemption.
#[test]
fn recordings_readme_describes_shared_chunks() {
    let d = FrameBuffering::default();
    assert_eq!(d.max_bytes, 1 << 20);
    assert_eq!(d.max_wait, std::time::Duration::from_secs(1));
    for stale in [
        "Every frame is its own chunk",
        "every finished frame and message is readable",
    ] {
        assert!(!RECORDINGS_README.contains(stale), "stale: {stale:?}");
    }
    assert!(RECORDINGS_README.contains("up to 1 s or 1 MiB"));
    assert!(README.contains("up to 1 s of wall time\nor 1 MiB"));
    let exempt = format!("`RATIO_FREE_BYTES` ({} MiB)", RATIO_FREE_BYTES >> 20);
    assert!(RECORDINGS_README.contains(&exempt), "{exempt}");
}
