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
        #[source]
        problem: PlacesProblem,
    },
}

/// What makes a places file of the right shape unusable.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlacesProblem {
    /// Another `format`.
    #[error("format is {found:?}, not {PLACES_FORMAT:?}")]
    Format {
        /// The file's `format`.
        found: String,
    },
    /// Another `version`.
    #[error("places version {found} (this eotn reads version {PLACES_VERSION})")]
    Version {
        /// The file's `version`.
        found: u32,
    },
    /// Two objects with one id.
    #[error("object id {id} appears twice")]
    IdTwice {
        /// The id.
        id: usize,
    },
    /// A position that is not finite.
    #[error("object {id}: position is not a number")]
    Position {
        /// The object's id.
        id: usize,
    },
    /// A height that is not finite.
    #[error("object {id}: height is not a number")]
    Height {
        /// The object's id.
        id: usize,
    },
    /// An object without patterns.
    #[error("object {id}: no patterns")]
    NoPatterns {
        /// The object's id.
        id: usize,
    },
    /// A pattern cell that is no class code.
    #[error("object {id}: {code} is not a class code")]
    ClassCode {
        /// The object's id.
        id: usize,
        /// The cell's value.
        code: u8,
    },
    /// A size relation whose distances do not shrink with size.
    #[error(
        "size relation distance = {multiplier_cm_px} / size + {offset_cm} is not a relation \
         (the multiplier must be a positive number)"
    )]
    Relation {
        /// Its multiplier, cm × px.
        multiplier_cm_px: f64,
        /// Its offset, cm.
        offset_cm: f64,
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

    fn check(&self) -> Result<(), PlacesProblem> {
        if self.format != PLACES_FORMAT {
            return Err(PlacesProblem::Format {
                found: self.format.clone(),
            });
        }
        if self.version != PLACES_VERSION {
            return Err(PlacesProblem::Version {
                found: self.version,
            });
        }
        let mut ids: Vec<usize> = self.objects.iter().map(|o| o.id).collect();
        ids.sort_unstable();
        if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
            return Err(PlacesProblem::IdTwice { id: w[0] });
        }
        for o in &self.objects {
            if !o.field_cm.iter().all(|v| v.is_finite()) {
                return Err(PlacesProblem::Position { id: o.id });
            }
            if o.height_cm.is_some_and(|h| !h.is_finite()) {
                return Err(PlacesProblem::Height { id: o.id });
            }
            if o.patterns.is_empty() {
                return Err(PlacesProblem::NoPatterns { id: o.id });
            }
            for p in &o.patterns {
                if let Some(c) =
                    p.0.iter()
                        .flatten()
                        .find(|&&c| ColourClass::from_code(c).is_none())
                {
                    return Err(PlacesProblem::ClassCode { id: o.id, code: *c });
                }
            }
        }
        if let Some(r) = &self.relation
            && !(r.multiplier_cm_px.is_finite()
                && r.multiplier_cm_px > 0.0
                && r.offset_cm.is_finite())
        {
            return Err(PlacesProblem::Relation {
                multiplier_cm_px: r.multiplier_cm_px,
                offset_cm: r.offset_cm,
            });
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
