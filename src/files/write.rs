//! The one safe-write path. Every file strata writes is written to a temporary file created
//! exclusively (`O_EXCL`, an unpredictable name, `tempfile`) beside its target, fsynced and renamed
//! over the target, then the directory is fsynced (best effort):
//!
//! - a reader never sees a partial file; a failed write (a full disk, `EFBIG` under a file-size
//!   limit) removes the temporary file and leaves an existing target as it was;
//! - the target must be a regular file or a new name ([`check_target`]): a link, directory, device
//!   or FIFO is refused, never written through; a link planted at a temporary name is never followed;
//! - the new file gets the mode of the file it replaces, or for a new name `0666` less the umask
//!   (0644 under umask 022), as any program creating a file would.
//!
//! [`StemLock`] is the advisory lock a render holds on its output stem, so a second render to the
//! same `-o` is refused instead of interleaving its images with the first's.

use std::fs::{self, File};
use std::io::{self, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

/// The longest file name (bytes) the file systems strata writes to accept.
pub const NAME_MAX: usize = 255;
/// What a temporary name adds to its target's name: `.` + name + `.` + 6 random characters + `.tmp`.
pub const TEMP_NAME_EXTRA: usize = 12;

/// The directory `path` is written in ("." for a bare name).
pub fn dir_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Refuses an output path that is neither a regular file nor a new name, saying what it is: a
/// symbolic link (even to a regular file: the link would be replaced, or its target clobbered), a
/// directory, a device, a FIFO or a socket (replacing `/dev/null` would break the system).
pub fn check_target(path: &Path) -> io::Result<()> {
    let meta = match fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    let t = meta.file_type();
    if t.is_file() {
        return Ok(());
    }
    let what = if t.is_symlink() {
        "a symbolic link"
    } else if t.is_dir() {
        "a directory"
    } else {
        "a device, FIFO or socket"
    };
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("is {what}; strata writes only regular files or new names (it replaces the file)"),
    ))
}

/// A file being written safely: a temporary file beside the target, renamed over it by
/// [`AtomicFile::commit`]; dropped uncommitted, the temporary file is removed.
pub struct AtomicFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl AtomicFile {
    /// Creates the temporary file for `path` (checked with [`check_target`]), with the mode of
    /// the file it will replace, or `0666` less the umask.
    pub fn create(path: &Path) -> io::Result<Self> {
        check_target(path)?;
        let dir = dir_of(path);
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let replaced = fs::symlink_metadata(path).ok().map(|m| m.mode() & 0o7777);
        // Created with 0666: the kernel applies the umask, as for any new file.
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .permissions(fs::Permissions::from_mode(0o666))
            .tempfile_in(&dir)?;
        if let Some(mode) = replaced {
            tmp.as_file().set_permissions(fs::Permissions::from_mode(mode))?;
        }
        Ok(Self { tmp, path: path.to_path_buf() })
    }

    /// The open temporary file, to write to.
    pub fn file(&mut self) -> &mut File {
        self.tmp.as_file_mut()
    }

    /// Fsyncs the temporary file, renames it over the target (checked again: a link or special
    /// file put there meanwhile is refused) and fsyncs the directory (best effort).
    pub fn commit(self) -> io::Result<()> {
        self.tmp.as_file().sync_all()?;
        check_target(&self.path)?;
        self.tmp.persist(&self.path).map_err(|e| e.error)?;
        if let Ok(d) = File::open(dir_of(&self.path)) {
            let _ = d.sync_all();
        }
        Ok(())
    }
}

/// Writes `bytes` to `path` atomically through an [`AtomicFile`]. On failure the temporary file is
/// removed and an existing file at `path` is left untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.file().write_all(bytes)?;
    f.commit()
}

/// The advisory lock (`flock`, exclusive, not waiting) a render holds on its output stem: the file
/// `.NAME.lock` beside the stem, removed when the lock is dropped. A second render to the same stem
/// finds it locked and is refused.
pub struct StemLock {
    file: File,
    path: PathBuf,
}

impl StemLock {
    /// The lock file of output stem `stem`.
    pub fn path_of(stem: &Path) -> PathBuf {
        let name = stem.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        dir_of(stem).join(format!(".{name}.lock"))
    }

    /// Takes the lock of `stem`, or fails at once with `WouldBlock` if another process holds it.
    /// The lock file is opened without following a link; a lock file removed by its holder between
    /// our open and our lock is noticed (its inode is no longer at the path) and opened again.
    pub fn acquire(stem: &Path) -> io::Result<Self> {
        let path = Self::path_of(stem);
        loop {
            let file = fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .mode(0o666)
                .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
                .open(&path)?;
            if !file.metadata()?.file_type().is_file() {
                return Err(io::Error::new(io::ErrorKind::InvalidInput, "the lock file is not a regular file"));
            }
            match file.try_lock() {
                Ok(()) => {}
                Err(fs::TryLockError::WouldBlock) => {
                    return Err(io::Error::new(
                        io::ErrorKind::WouldBlock,
                        format!(
                        "another strata process is writing this output (it holds {}); wait for it or use another -o",
                        path.display()
                    ),
                    ))
                }
                Err(fs::TryLockError::Error(e)) => return Err(e),
            }
            let same = fs::symlink_metadata(&path)
                .is_ok_and(|m| file.metadata().is_ok_and(|f| f.ino() == m.ino() && f.dev() == m.dev()));
            if same {
                return Ok(Self { file, path });
            }
        }
    }
}

impl Drop for StemLock {
    fn drop(&mut self) {
        // Removed while still locked, so a waiting process sees the inode gone and opens anew.
        let _ = fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("strata-write-{name}-{}", std::process::id()));
        fs::remove_dir_all(&dir).ok();
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn new_files_get_the_umask_mode_and_replaced_files_keep_theirs() {
        let dir = scratch("mode");
        let new = dir.join("new.txt");
        write_atomic(&new, b"x").unwrap();
        // The umask of this process, as the kernel applies it to a plain create.
        let probe = dir.join("probe");
        File::create(&probe).unwrap();
        let want = fs::metadata(&probe).unwrap().mode() & 0o777;
        assert_eq!(fs::metadata(&new).unwrap().mode() & 0o777, want, "like any new file");
        let old = dir.join("old.txt");
        fs::write(&old, b"old").unwrap();
        fs::set_permissions(&old, fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&old, b"new").unwrap();
        assert_eq!(fs::metadata(&old).unwrap().mode() & 0o777, 0o640);
        assert_eq!(fs::read(&old).unwrap(), b"new");
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 3, "no temporary file left");
        fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_held_stem_lock_refuses_a_second_and_is_removed_after() {
        let dir = scratch("lock");
        let stem = dir.join("out");
        let a = StemLock::acquire(&stem).unwrap();
        let e = StemLock::acquire(&stem).err().expect("held");
        assert_eq!(e.kind(), io::ErrorKind::WouldBlock);
        assert!(e.to_string().contains("another strata process"), "{e}");
        drop(a);
        assert!(!StemLock::path_of(&stem).exists());
        drop(StemLock::acquire(&stem).unwrap());
        fs::remove_dir_all(&dir).ok();
    }
}
