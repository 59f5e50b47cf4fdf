//! The one bounded reader. Every file strata reads (scenes, OBJ/MTL, point sets, checkpoints, EXR
//! references) is opened here:
//!
//! 1. [`open_regular`] refuses what is not a regular file (a FIFO, a device, a directory, a socket,
//!    or a link to one) from its metadata *before* opening it, so a FIFO cannot block the open and
//!    `/dev/zero` cannot be read forever; the file is opened non-blocking and checked again on the
//!    open descriptor, so one swapped in between is refused too.
//! 2. [`read_bounded`] checks the size against the caller's limit before reading a byte, and
//!    reads at most the limit (a file that grows while read is refused, not followed).
//! 3. Format readers check their magic or header first ([`read_exact_len`] reads a known prefix)
//!    and refuse trailing bytes after what the header declares.
//!
//! Errors are `io::Error`s whose message says what was wrong (`is a FIFO; strata reads only
//! regular files`, `is N bytes, above the limit of M bytes`), so each format keeps its own typed
//! error with the path. For the Mitsuba XML reader (or any new format): call
//! `read_bounded(path, limits.max_file_bytes)` and parse the bytes; never `std::fs::read`.

use std::fs::{self, File};
use std::io::{self, Read};
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;

/// What a file that is not a regular file is, for messages.
fn kind_of(t: fs::FileType) -> &'static str {
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

fn refused(t: fs::FileType) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, format!("is {}; strata reads only regular files", kind_of(t)))
}

/// Opens `path` for reading if it is a regular file (a link is followed to its target, which must
/// be one), returning the file and its size. A FIFO, device, directory or socket is refused before
/// it is opened.
pub fn open_regular(path: &Path) -> io::Result<(File, u64)> {
    let meta = fs::metadata(path)?;
    if !meta.file_type().is_file() {
        return Err(refused(meta.file_type()));
    }
    let file = fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK).open(path)?;
    let meta = file.metadata()?;
    if !meta.file_type().is_file() {
        return Err(refused(meta.file_type()));
    }
    Ok((file, meta.len()))
}

/// The message of a file over its size limit.
pub fn too_large(len: u64, max: u64) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, format!("is {len} bytes, above the limit of {max} bytes"))
}

/// Reads the whole of regular file `path` ([`open_regular`]) if it has at most `max` bytes: the
/// size is checked before reading, and no more than `max` bytes are ever read.
pub fn read_bounded(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    let (file, len) = open_regular(path)?;
    if len > max {
        return Err(too_large(len, max));
    }
    read_all_of(file, len, max)
}

/// Reads what is left of `file` (whose size was `len`), refusing more than `max` bytes.
pub fn read_all_of(file: File, len: u64, max: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::with_capacity(len.min(max) as usize);
    file.take(max.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return Err(too_large(bytes.len() as u64, max));
    }
    Ok(bytes)
}

/// Reads exactly `n` bytes from `file` (a header or a magic number), or as many as there are
/// before the end: the caller compares the length with what it needed.
pub fn read_exact_len(file: &mut File, n: usize) -> io::Result<Vec<u8>> {
    let mut out = Vec::with_capacity(n);
    file.take(n as u64).read_to_end(&mut out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_are_refused_before_opening_and_sizes_before_reading() {
        let e = read_bounded(Path::new("/dev/zero"), 1 << 20).unwrap_err().to_string();
        assert!(e.contains("is a device"), "{e}");
        let e = read_bounded(Path::new("/"), 1 << 20).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        let dir = std::env::temp_dir().join(format!("strata-read-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        let e = read_bounded(&fifo, 1 << 20).unwrap_err().to_string();
        assert!(e.contains("is a FIFO"), "{e}");
        let f = dir.join("ten");
        fs::write(&f, [7u8; 10]).unwrap();
        assert_eq!(read_bounded(&f, 10).unwrap(), vec![7u8; 10]);
        let e = read_bounded(&f, 9).unwrap_err().to_string();
        assert!(e.contains("is 10 bytes, above the limit of 9 bytes"), "{e}");
        let link = dir.join("link");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        assert!(read_bounded(&link, 1 << 20).unwrap_err().to_string().contains("is a device"));
        fs::remove_dir_all(&dir).ok();
    }
}
