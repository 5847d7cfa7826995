//! The one rule for reading an input file (scene file, OBJ, texture): follow symlinks, accept
//! only a regular file of at most [`MAX_INPUT_FILE_BYTES`], and read it whole. A directory, a
//! FIFO (which would block forever), a device such as `/dev/zero` (which never ends) or a
//! socket is refused before it is opened.

use crate::limits::MAX_INPUT_FILE_BYTES;
use std::io::Read;
use std::path::Path;

/// The bytes of the input file at `path`, or why it cannot be read (without the path: the
/// caller's error names the file).
pub fn read_input_file(path: &Path) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    check_kind_and_size(&meta)?;
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    // The file may have been replaced or grown since: check what was opened, read one byte
    // past the limit to notice a file that grew.
    check_kind_and_size(&file.metadata().map_err(|e| e.to_string())?)?;
    let mut bytes = Vec::new();
    file.take(MAX_INPUT_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_INPUT_FILE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// A regular file within the size limit, else what it is.
fn check_kind_and_size(meta: &std::fs::Metadata) -> Result<(), String> {
    let kind = meta.file_type();
    if kind.is_dir() {
        return Err("is a directory, not a file".into());
    }
    if !kind.is_file() {
        return Err(format!("is {}, not a regular file", special_kind(&kind)));
    }
    if meta.len() > MAX_INPUT_FILE_BYTES {
        return Err(too_large(meta.len()));
    }
    Ok(())
}

fn too_large(len: u64) -> String {
    format!(
        "is {len} bytes, more than the {} MiB limit for input files",
        MAX_INPUT_FILE_BYTES >> 20
    )
}

/// Words for a file that is neither a regular file nor a directory.
#[cfg(unix)]
fn special_kind(kind: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if kind.is_fifo() {
        "a FIFO (named pipe)"
    } else if kind.is_char_device() {
        "a character device"
    } else if kind.is_block_device() {
        "a block device"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

/// Words for a file that is neither a regular file nor a directory.
#[cfg(not(unix))]
fn special_kind(_kind: &std::fs::FileType) -> &'static str {
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_only() {
        let dir = std::env::temp_dir().join(format!("penumbra-input-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.txt");
        std::fs::write(&f, "abc").unwrap();
        assert_eq!(read_input_file(&f).unwrap(), b"abc");
        assert_eq!(
            read_input_file(&dir).unwrap_err(),
            "is a directory, not a file"
        );
        assert!(read_input_file(&dir.join("none")).is_err());
        #[cfg(unix)]
        {
            let e = read_input_file(Path::new("/dev/zero")).unwrap_err();
            assert_eq!(e, "is a character device, not a regular file");
            let link = dir.join("zero.obj");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            assert_eq!(read_input_file(&link).unwrap_err(), e);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
