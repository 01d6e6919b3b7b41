//! ROS 2 bags (rosbag2): a folder with `metadata.yaml` and its storage files, one or several
//! (split bags), SQLite (`.db3`, Humble's default) or MCAP (the default since Iron), each file
//! possibly compressed whole with zstd or holding zstd-compressed messages.
//!
//! [`layout_of`] tells what a path given as a recording is (an MCAP file, a bag folder, a bag's
//! `metadata.yaml`, a storage file with or without `metadata.yaml` beside it) and lists the
//! storage files to read in order; [`super::StreamReader`] reads them as one recording.

pub(crate) mod db3;
pub mod metadata;

use std::path::{Path, PathBuf};

pub use metadata::{BagCompression, BagMetadata, MetadataError};

use super::StreamError;
use crate::formats::MessageKind;

/// The storage of one file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StorageKind {
    /// MCAP.
    Mcap,
    /// SQLite (`.db3`).
    Sqlite,
}

/// One storage file to read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StoragePart {
    /// The file.
    pub path: PathBuf,
    /// Its storage.
    pub kind: StorageKind,
    /// Compressed whole with zstd (decompressed into a temporary file to read).
    pub zstd_file: bool,
}

/// What to read for a recording path.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Layout {
    /// The storage files, in order.
    pub parts: Vec<StoragePart>,
    /// Each message's bytes are zstd-compressed.
    pub zstd_messages: bool,
    /// The camera topic every file reads (the bag's first image topic), when a `metadata.yaml`
    /// says which.
    pub image_topic: Option<String>,
    /// The bag's metadata, when there is one.
    pub metadata: Option<BagMetadata>,
}

/// True for a folder holding `metadata.yaml`: a rosbag2 bag.
#[must_use]
pub fn is_bag_folder(path: &Path) -> bool {
    path.is_dir() && path.join("metadata.yaml").is_file()
}

/// The storage a file name says (`.mcap`, `.mcap.partial`, `.db3`, each maybe `.zstd`), and
/// whether it is compressed whole.
#[must_use]
pub fn storage_of_name(path: &Path) -> Option<(StorageKind, bool)> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let (base, zstd) = match name.strip_suffix(".zstd") {
        Some(b) => (b, true),
        None => (name.as_str(), false),
    };
    if base.ends_with(".mcap") || (!zstd && crate::streams::is_stream_file(Path::new(base))) {
        Some((StorageKind::Mcap, zstd))
    } else if base.ends_with(".db3") {
        Some((StorageKind::Sqlite, zstd))
    } else {
        None
    }
}

/// True when `path` names a recording eotn reads: an MCAP file, a rosbag2 folder or its
/// `metadata.yaml`, or a storage file (`.db3`, maybe `.zstd`).
#[must_use]
pub fn is_recording(path: &Path) -> bool {
    storage_of_name(path).is_some()
        || is_bag_folder(path)
        || path.file_name().is_some_and(|n| n == "metadata.yaml")
}

/// What to read for `path`.
///
/// # Errors
/// [`StreamError`] naming the path: a folder that is not a bag, a `metadata.yaml` that does not
/// parse or names no storage file that exists.
pub fn layout_of(path: &Path) -> Result<Layout, StreamError> {
    if path.file_name().is_some_and(|n| n == "metadata.yaml") {
        let dir = path.parent().unwrap_or(Path::new("."));
        return bag_layout(if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        });
    }
    if path.is_dir() {
        if !path.join("metadata.yaml").is_file() {
            return Err(StreamError::NotMcap {
                path: path.to_owned(),
                detail: "a folder without metadata.yaml is not a rosbag2 bag".to_owned(),
            });
        }
        return bag_layout(path);
    }
    let (kind, zstd_file) = storage_of_name(path).unwrap_or((StorageKind::Mcap, false));
    let mut layout = Layout {
        parts: vec![StoragePart {
            path: path.to_owned(),
            kind,
            zstd_file,
        }],
        ..Layout::default()
    };
    // A storage file of a bag: its metadata says whether messages are compressed.
    if let Some(dir) = path.parent().filter(|d| d.join("metadata.yaml").is_file())
        && let Ok(meta) = BagMetadata::load(dir)
    {
        layout.zstd_messages = meta.compression == BagCompression::ZstdMessages;
        layout.metadata = Some(meta);
    }
    Ok(layout)
}

fn bag_layout(dir: &Path) -> Result<Layout, StreamError> {
    let meta = BagMetadata::load(dir).map_err(|e| StreamError::Corrupt {
        path: dir.to_owned(),
        detail: e.to_string(),
    })?;
    let default_kind = match meta.storage_identifier.as_str() {
        "sqlite3" => Some(StorageKind::Sqlite),
        "mcap" => Some(StorageKind::Mcap),
        _ => None,
    };
    let mut names = meta.files.clone();
    if names.is_empty() {
        // No file named: every storage file in the folder, by name.
        let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|source| StreamError::Io {
                path: dir.to_owned(),
                source,
            })?
            .filter_map(Result::ok)
            .map(|e| PathBuf::from(e.file_name()))
            .filter(|n| storage_of_name(n).is_some())
            .collect();
        found.sort();
        names = found;
    }
    let zstd_files = meta.compression == BagCompression::ZstdFiles;
    let mut parts = Vec::new();
    let mut missing = Vec::new();
    for name in &names {
        let mut path = dir.join(name);
        // Compressed files are listed with or without their `.zstd`.
        if !path.is_file() && zstd_files {
            let mut z = path.clone().into_os_string();
            z.push(".zstd");
            path = PathBuf::from(z);
        }
        if !path.is_file() {
            missing.push(name.display().to_string());
            continue;
        }
        let (kind, zstd) = storage_of_name(&path)
            .or_else(|| default_kind.map(|k| (k, zstd_files)))
            .unwrap_or((StorageKind::Mcap, zstd_files));
        parts.push(StoragePart {
            path,
            kind,
            zstd_file: zstd,
        });
    }
    if parts.is_empty() {
        return Err(StreamError::Corrupt {
            path: dir.to_owned(),
            detail: if missing.is_empty() {
                "metadata.yaml names no storage file and the folder holds none".to_owned()
            } else {
                format!("the storage files are missing: {}", missing.join(", "))
            },
        });
    }
    let image_topic = meta
        .topics
        .iter()
        .filter(|t| t.message_count > 0 || meta.message_count == 0)
        .find(|t| {
            MessageKind::of(&t.type_name, &t.serialization_format)
                .is_some_and(MessageKind::is_image)
        })
        .map(|t| t.name.clone());
    let mut meta = meta;
    if !missing.is_empty() {
        meta.warnings.push(format!(
            "storage files missing, their frames are not read: {}",
            missing.join(", ")
        ));
    }
    Ok(Layout {
        parts,
        zstd_messages: meta.compression == BagCompression::ZstdMessages,
        image_topic,
        metadata: Some(meta),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_tell_the_storage() {
        for (name, want) in [
            ("a.mcap", Some((StorageKind::Mcap, false))),
            ("a.MCAP.partial", Some((StorageKind::Mcap, false))),
            ("b_0.db3", Some((StorageKind::Sqlite, false))),
            ("b_0.db3.zstd", Some((StorageKind::Sqlite, true))),
            ("b_0.mcap.zstd", Some((StorageKind::Mcap, true))),
            ("x.lut", None),
        ] {
            assert_eq!(storage_of_name(Path::new(name)), want, "{name}");
        }
    }

    #[test]
    fn folders_without_metadata_are_not_bags() {
        let dir = tempfile::tempdir().unwrap();
        let e = layout_of(dir.path()).unwrap_err().to_string();
        assert!(e.contains("not a rosbag2 bag"), "{e}");
        std::fs::write(
            dir.path().join("metadata.yaml"),
            "rosbag2_bagfile_information:\n  version: 5\n  relative_file_paths: [gone.db3]\n",
        )
        .unwrap();
        let e = layout_of(dir.path()).unwrap_err().to_string();
        assert!(e.contains("gone.db3"), "{e}");
        std::fs::write(dir.path().join("gone.db3"), b"").unwrap();
        let l = layout_of(&dir.path().join("metadata.yaml")).unwrap();
        assert_eq!(l.parts[0].kind, StorageKind::Sqlite);
    }
}
