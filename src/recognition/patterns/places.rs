//! The places file: `eotn.places` JSON, read with every field checked and written atomically.

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::PatternMemory;
use crate::lut::ColourClass;

/// The `format` of a places file.
pub const PLACES_FORMAT: &str = "eotn.places";

/// The places-file version this build writes and reads.
pub const PLACES_VERSION: u32 = 1;

pub(super) fn places_format() -> String {
    PLACES_FORMAT.to_owned()
}

pub(super) const fn places_version() -> u32 {
    PLACES_VERSION
}

/// Why a places file could not be read or written; every message names the file.
#[derive(Debug, Error)]
pub enum PlacesError {
    /// Reading or writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// Not JSON of the places shape.
    #[error("{path}: not a places file ({source})")]
    Parse {
        /// The file.
        path: PathBuf,
        /// Where and why parsing stopped.
        source: serde_json::Error,
    },
    /// JSON of the right shape with values that make no sense.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

impl PatternMemory {
    /// Reads a places file written by [`Self::save`] (`eotn patterns learn`), checking every
    /// field: format and version, unique ids, finite positions, class codes, a relation whose
    /// distances shrink with size.
    ///
    /// # Errors
    /// [`PlacesError`] naming the file and the problem.
    pub fn load(path: &Path) -> Result<Self, PlacesError> {
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SIDE_FILE_BYTES,
            "a places file",
        )
        .map_err(|source| PlacesError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_json(&text).map_err(|e| match e {
            PlacesError::Parse { source, .. } => PlacesError::Parse {
                path: path.to_owned(),
                source,
            },
            PlacesError::Invalid { problem, .. } => PlacesError::Invalid {
                path: path.to_owned(),
                problem,
            },
            other @ PlacesError::Io { .. } => other,
        })
    }

    /// Parses and checks places JSON (see [`Self::load`]); errors name no file.
    ///
    /// # Errors
    /// [`PlacesError::Parse`] or [`PlacesError::Invalid`] with an empty path.
    pub fn from_json(text: &str) -> Result<Self, PlacesError> {
        let memory: Self = serde_json::from_str(text).map_err(|source| PlacesError::Parse {
            path: PathBuf::new(),
            source,
        })?;
        memory.check().map_err(|problem| PlacesError::Invalid {
            path: PathBuf::new(),
            problem,
        })?;
        Ok(memory)
    }

    fn check(&self) -> Result<(), String> {
        if self.format != PLACES_FORMAT {
            return Err(format!(
                "format is {:?}, not {PLACES_FORMAT:?}",
                self.format
            ));
        }
        if self.version != PLACES_VERSION {
            return Err(format!(
                "places version {} (this eotn reads version {PLACES_VERSION})",
                self.version
            ));
        }
        let mut ids: Vec<usize> = self.objects.iter().map(|o| o.id).collect();
        ids.sort_unstable();
        if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("object id {} appears twice", w[0]));
        }
        for o in &self.objects {
            if !o.field_cm.iter().all(|v| v.is_finite()) {
                return Err(format!("object {}: position is not a number", o.id));
            }
            if o.height_cm.is_some_and(|h| !h.is_finite()) {
                return Err(format!("object {}: height is not a number", o.id));
            }
            if o.patterns.is_empty() {
                return Err(format!("object {}: no patterns", o.id));
            }
            for p in &o.patterns {
                if let Some(c) =
                    p.0.iter()
                        .flatten()
                        .find(|&&c| ColourClass::from_code(c).is_none())
                {
                    return Err(format!("object {}: {c} is not a class code", o.id));
                }
            }
        }
        if let Some(r) = &self.relation
            && !(r.multiplier_cm_px.is_finite()
                && r.multiplier_cm_px > 0.0
                && r.offset_cm.is_finite())
        {
            return Err(format!(
                "size relation distance = {} / size + {} is not a relation (the multiplier \
                 must be a positive number)",
                r.multiplier_cm_px, r.offset_cm
            ));
        }
        Ok(())
    }

    /// Writes the places file atomically (temporary file, fsync, rename), pretty-printed.
    ///
    /// # Errors
    /// [`PlacesError::Io`] naming the file.
    pub fn save(&self, path: &Path) -> Result<(), PlacesError> {
        let io = |source| PlacesError::Io {
            path: path.to_owned(),
            source,
        };
        let json = serde_json::to_vec_pretty(self).map_err(|e| io(std::io::Error::other(e)))?;
        crate::atomic_file::write_atomic(path, &json).map_err(io)
    }
}
