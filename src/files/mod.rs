//! Files on disk, for every subcommand: the one bounded reader ([`read`]), the one safe-write path
//! ([`write`]: exclusive temporary file, rename, the mode from the umask or the replaced file's,
//! the advisory lock of a render's output stem) and the output plan ([`plan`]: the inputs and
//! outputs a subcommand declares, checked together before any work).
//!
//! This is the bottom layer for file access: it imports nothing of strata. Readers of a new format
//! (a scene, a point set, an image) open their files through [`read::open_regular`] or
//! [`read::read_bounded`]; writers go through [`write::write_atomic`] or [`write::AtomicFile`].

pub mod plan;
pub mod read;
pub mod write;

pub use plan::{Plan, PlanError, Role};
pub use read::{open_regular, read_bounded, read_exact_len};
pub use write::{check_target, dir_of, write_atomic, AtomicFile, StemLock, NAME_MAX, TEMP_NAME_EXTRA};
