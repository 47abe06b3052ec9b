//! Reading input files: the scene file given on the command line, the points CSV of
//! `magsep field`, and the files a scene names (`[[fibre_packings]] recording`).
//!
//! Every input must be a regular file (after following symbolic links): directories,
//! devices such as `/dev/zero`, FIFOs and sockets are refused before they are opened, so
//! nothing blocks or reads without end. Text inputs have a size cap, checked against the
//! file's size before reading and enforced while reading (a file that grows is cut off):
//!
//! | input | cap |
//! |---|---|
//! | scene file (`magsep run`, `validate`, `field`; [`crate::scene::load_scene`]) | [`MAX_SCENE_BYTES`] = 16 MiB |
//! | points CSV (`magsep field --points`) | [`MAX_POINTS_BYTES`] = 256 MiB |
//! | recording named in a scene | [`MAX_NAMED_RECORDING_BYTES`] = 4 GiB, read as a stream (one chunk and the last frame in memory) |
//!
//! Errors name the file and what is wrong, never its contents.

use std::io::Read;
use std::path::{Path, PathBuf};

use magsep_plugins::record::{LastFrame, open_regular, read_last_frame};

/// Largest scene file (bytes): 16 MiB. The largest shipped scene is under 4 KiB; a scene
/// listing 10^5 particle positions explicitly is about 8 MiB.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Largest points CSV of `magsep field --points` (bytes): 256 MiB (about 4 million points).
pub const MAX_POINTS_BYTES: u64 = 256 << 20;

/// Largest recording a scene may name (`[[fibre_packings]] recording`), bytes: 4 GiB.
pub const MAX_NAMED_RECORDING_BYTES: u64 = 4 << 30;

/// The size of the regular file at `path`, or why it cannot be an input.
fn regular_size(path: &Path, cap: u64) -> Result<u64, String> {
    let meta =
        std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "cannot read {}: not a regular file (a directory, device, FIFO or socket)",
            path.display()
        ));
    }
    if meta.len() > cap {
        return Err(format!(
            "cannot read {}: it has {} bytes, more than the limit of {cap} bytes",
            path.display(),
            meta.len()
        ));
    }
    Ok(meta.len())
}

/// The text of the regular file at `path`, at most `cap` bytes.
///
/// # Errors
/// A message naming the file: missing, unreadable, not a regular file, larger than `cap`,
/// not UTF-8.
pub fn read_text(path: &Path, cap: u64) -> Result<String, String> {
    let size = regular_size(path, cap)?;
    let file = open_regular(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if bytes.len() as u64 > cap {
        return Err(format!(
            "cannot read {}: it grew beyond the limit of {cap} bytes while being read",
            path.display()
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "cannot read {}: not UTF-8 text (invalid byte at offset {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}

/// The text of a scene file ([`MAX_SCENE_BYTES`]).
///
/// # Errors
/// As [`read_text`].
pub fn read_scene_text(path: &Path) -> Result<String, String> {
    read_text(path, MAX_SCENE_BYTES)
}

/// The last complete frame of a recording a scene names: a regular file of at most
/// [`MAX_NAMED_RECORDING_BYTES`], streamed.
///
/// # Errors
/// A message naming the file; recording errors never quote the file's bytes.
pub fn read_named_recording(path: &Path) -> Result<LastFrame, String> {
    regular_size(path, MAX_NAMED_RECORDING_BYTES)?;
    read_last_frame(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

/// The input files a scene's text names (`[[fibre_packings]] recording`), as written
/// (relative to the working directory); empty when the text does not parse.
pub fn named_inputs(scene_text: &str) -> Vec<PathBuf> {
    let Ok(table) = scene_text.parse::<toml::Table>() else {
        return Vec::new();
    };
    table
        .get("fibre_packings")
        .and_then(toml::Value::as_array)
        .map(|entries| {
            entries
                .iter()
                .filter_map(|e| e.get("recording")?.as_str().map(PathBuf::from))
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn inputs_must_be_regular_files_of_bounded_size() {
        let dir = std::env::temp_dir().join(format!("magsep-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let err = read_scene_text(&dir).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
        let err = read_scene_text(Path::new("/dev/zero")).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
        let big = dir.join("big.toml");
        std::fs::write(&big, vec![b'#'; 2000]).unwrap();
        let err = read_text(&big, 1000).unwrap_err();
        assert!(err.contains("2000 bytes") && err.contains("1000"), "{err}");
        assert_eq!(read_text(&big, 2000).unwrap().len(), 2000);
        let bin = dir.join("bin.toml");
        std::fs::write(&bin, b"a = 1\n\xff\xfe").unwrap();
        let err = read_scene_text(&bin).unwrap_err();
        assert!(err.contains("offset 6") && !err.contains("a = 1"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn named_inputs_lists_fibre_packing_recordings() {
        let text = "[[fibre_packings]]\nrecording = \"a.mcap\"\n[[fibre_packings]]\n\
                    recording = \"dir/b.mcap\"\n";
        assert_eq!(
            named_inputs(text),
            vec![PathBuf::from("a.mcap"), PathBuf::from("dir/b.mcap")]
        );
        assert!(named_inputs("not toml [").is_empty());
    }
}
