//! Importers for other teams' recordings: their frames and sensor logs, brought into our frame
//! and sensor types so the whole pipeline, the app and the stream tools work on real data.
//!
//! [`bhuman`] reads the B-Human 2009 Nao log (`../shared/data/bhuman2009/`); `eotn import`
//! writes what it reads as a stream.

pub mod bhuman;
