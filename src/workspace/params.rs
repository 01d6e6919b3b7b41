//! Recognition parameters in the app: the set in use and the file it came from, opening one
//! (File ▸ Open parameters…, a `.json` recognised by its content, the set a stream names),
//! tuning one value at a time with the frame re-run at once, resetting a value to the file's,
//! saving as a parameters file, and trying a change over the whole stream.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context as _;
use serde_json::Value;

use super::source::Source;
use super::stream_scan::StreamScan;
use super::{ParamsCommand, Workspace};
use crate::lut::LookupTable;
use crate::pipeline::{Pipeline, PipelineParams};
use crate::recognition::{Recognition, RecognitionParams, params_file};

/// The recognition parameters' origin and what the open stream asks for.
#[derive(Debug, Clone, Default)]
pub struct ParamsSlot {
    /// The parameters file opened or saved last (`None`: the built-in defaults).
    pub path: Option<PathBuf>,
    /// The parameters as opened or saved: what "Reset" returns a value to.
    pub loaded: RecognitionParams,
    /// The parameter set the open stream names when it is not the one in use.
    pub offer: Option<ParamsOffer>,
    /// The whole-stream check of the tuned parameters against the loaded ones.
    pub try_run: Option<TryParams>,
}

/// A parameter set named by the open stream (its `eotn.recognition` metadata or source kind).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParamsOffer {
    /// The set's name (`"spl2009"`).
    pub name: String,
    /// Its file when found (`params/NAME.json` beside or above the stream, or in the current
    /// folder); `None` when not found.
    pub path: Option<PathBuf>,
}

/// What a `.json` file given to Open is, told by its content.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JsonKind {
    /// Recognition parameters (every key a parameter, e.g. `params/spl2009.json`).
    Params,
    /// A places file (`eotn patterns learn`).
    Places,
}

/// Tells a parameters file from a places file by its top-level keys: a parameters file has only
/// keys of [`RecognitionParams`] (an empty object is parameters too: all defaults).
///
/// # Errors
/// Unreadable files and text that is not a JSON object.
pub fn json_kind(path: &Path) -> anyhow::Result<JsonKind> {
    let text = crate::input_file::read_text_bounded(
        path,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "a JSON file",
    )
    .with_context(|| path.display().to_string())?;
    let value: Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let Value::Object(keys) = value else {
        anyhow::bail!("{}: not a JSON object", path.display());
    };
    let known = serde_json::to_value(RecognitionParams::default())?;
    let is_param = |k: &String| known.get(k).is_some();
    Ok(if keys.keys().all(is_param) {
        JsonKind::Params
    } else {
        JsonKind::Places
    })
}

/// Where a set named `name` is looked for: `params/NAME.json` in the stream's folder and up to
/// three folders above it, then in the current folder.
#[must_use]
pub fn find_param_set(name: &str, stream: &Path) -> Option<PathBuf> {
    if name.is_empty() || name.contains(['/', '\\']) || name.contains("..") {
        return None;
    }
    let file = format!("{name}.json");
    let stream = std::fs::canonicalize(stream).unwrap_or_else(|_| stream.to_owned());
    let mut places: Vec<PathBuf> = stream
        .ancestors()
        .skip(1)
        .take(4)
        .map(Path::to_owned)
        .collect();
    places.push(PathBuf::from("."));
    places
        .into_iter()
        .map(|dir| dir.join("params").join(&file))
        .find(|p| p.is_file())
}

/// The file of a parameter set as a camera names it (`CameraFiles::params`): a path (with a `/`
/// or ending in `.json`) as it is, a shipped set's name found by [`find_param_set`].
#[must_use]
pub fn named_param_file(name: &str, recording: &Path) -> Option<PathBuf> {
    if name.contains('/') || name.ends_with(".json") {
        Some(PathBuf::from(name))
    } else {
        find_param_set(name, recording)
    }
}

/// The values of `params` that differ from the defaults, as a parameters file holds them.
#[must_use]
pub fn differences_from_defaults(params: &RecognitionParams) -> Value {
    let full = serde_json::to_value(params).unwrap_or(Value::Null);
    let defaults = serde_json::to_value(RecognitionParams::default()).unwrap_or(Value::Null);
    difference(&full, &defaults).unwrap_or_else(|| Value::Object(serde_json::Map::new()))
}

fn difference(v: &Value, base: &Value) -> Option<Value> {
    match (v, base) {
        (Value::Object(a), Value::Object(b)) => {
            let m: serde_json::Map<String, Value> = a
                .iter()
                .filter_map(|(k, x)| {
                    let d = match b.get(k) {
                        Some(y) => difference(x, y)?,
                        None => x.clone(),
                    };
                    Some((k.clone(), d))
                })
                .collect();
            (!m.is_empty()).then_some(Value::Object(m))
        }
        _ => (v != base).then(|| v.clone()),
    }
}

/// One line per accepted object (`ball 123 cm`, `yellow goal 452 cm`), what a parameter change
/// is judged by; `nothing` when nothing was accepted.
#[must_use]
pub fn recognition_summary(r: &Recognition) -> String {
    let mut parts = Vec::new();
    for c in r.ball.candidates.iter().filter(|c| c.accepted) {
        parts.push(format!("ball {:.0} cm", c.camera.distance_cm));
    }
    for g in r.goals.candidates.iter().filter(|c| c.accepted) {
        parts.push(format!(
            "{} goal {:.0} cm",
            g.colour.name(),
            g.camera.distance_cm
        ));
    }
    for b in r.beacons.iter().filter(|b| b.accepted) {
        parts.push(format!("{} {:.0} cm", b.kind.name(), b.camera.distance_cm));
    }
    let markers = r.patterns.iter().filter(|p| p.accepted).count();
    if markers > 0 {
        parts.push(format!("{markers} markers"));
    }
    if parts.is_empty() {
        "nothing".to_owned()
    } else {
        parts.join(", ")
    }
}

/// One frame whose recognition the parameter change alters.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TryParamsRow {
    /// Frame index.
    pub index: usize,
    /// What was recognised with the loaded parameters.
    pub before: String,
    /// What is recognised with the tuned ones.
    pub after: String,
}

/// The whole-stream check of a parameter change, a few frames per UI frame.
#[derive(Debug, Clone)]
pub struct TryParams {
    before: Pipeline,
    after: Pipeline,
    /// The changed values (`ball.diameter_cm: 8.5 -> 8.6`).
    pub changes: Vec<String>,
    /// The frames read so far and those whose recognition changes.
    pub stream: StreamScan<TryParamsRow>,
}

impl TryParams {
    /// A check of `after` against `before` with table `lut` over `total` frames.
    #[must_use]
    pub fn new(
        lut: &LookupTable,
        before: PipelineParams,
        after: PipelineParams,
        total: usize,
    ) -> Self {
        let a = serde_json::to_value(before.recognition).unwrap_or(Value::Null);
        let b = serde_json::to_value(after.recognition).unwrap_or(Value::Null);
        let mut changes = Vec::new();
        list_changes(&a, &b, "", &mut changes);
        Self {
            before: Pipeline::new(lut.clone(), before),
            after: Pipeline::new(lut.clone(), after),
            changes,
            stream: StreamScan::new(total),
        }
    }

    /// True when every frame was scanned.
    #[must_use]
    pub const fn done(&self) -> bool {
        self.stream.done()
    }

    /// Scans frames of `src` for up to `budget`.
    pub fn scan(&mut self, src: &mut Source, budget: Duration) {
        let (before_pipeline, after_pipeline) = (&mut self.before, &mut self.after);
        self.stream.scan(src, budget, |index, f| {
            let sensors = f.sensors.as_ref();
            let before =
                recognition_summary(before_pipeline.process(&f.frame, sensors).recognition);
            let after = recognition_summary(after_pipeline.process(&f.frame, sensors).recognition);
            (before != after).then_some(TryParamsRow {
                index,
                before,
                after,
            })
        });
    }
}

fn list_changes(a: &Value, b: &Value, key: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in x {
                let sub = if key.is_empty() {
                    k.clone()
                } else {
                    format!("{key}.{k}")
                };
                if let Some(w) = y.get(k) {
                    list_changes(v, w, &sub, out);
                }
            }
        }
        _ if a != b => out.push(format!("{key}: {a} -> {b}")),
        _ => {}
    }
}

impl Workspace {
    /// The recognition parameters in use.
    #[must_use]
    pub fn recognition_params(&self) -> &RecognitionParams {
        &self.pipeline.params().recognition
    }

    /// Where the parameters came from and what the stream asks for.
    #[must_use]
    pub const fn params_slot(&self) -> &ParamsSlot {
        &self.params
    }

    /// True when a value was tuned since the parameters were opened or saved.
    #[must_use]
    pub fn params_modified(&self) -> bool {
        self.params.loaded != *self.recognition_params()
    }

    /// Applies the parameter commands (the rest of [`Workspace::apply`]).
    pub(super) fn apply_params(&mut self, command: ParamsCommand) -> anyhow::Result<()> {
        match command {
            ParamsCommand::OpenParams(p) => self.open_params(&p)?,
            ParamsCommand::UseOfferedParams => {
                let p = self
                    .params
                    .offer
                    .as_ref()
                    .and_then(|o| o.path.clone())
                    .context("the stream names no parameter set that was found")?;
                self.open_params(&p)?;
            }
            ParamsCommand::DefaultParams => self.default_params(),
            ParamsCommand::SetParamValue { pointer, value } => {
                self.set_param_value(&pointer, value)?
            }
            ParamsCommand::ResetParamValue(pointer) => self.reset_param_value(&pointer)?,
            ParamsCommand::ResetParams => self.reset_params(),
            ParamsCommand::SaveParams(p) => self.save_params(&p)?,
            ParamsCommand::TryParamsOnStream => self.try_params_on_stream()?,
        }
        Ok(())
    }

    pub(super) fn open_params(&mut self, path: &Path) -> anyhow::Result<()> {
        let p = params_file::load(path)?;
        self.set_recognition_params(p);
        self.params.loaded = p;
        self.params.path = Some(path.to_owned());
        self.params.try_run = None;
        let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned());
        self.remember_for_camera(|f| f.params = Some(canonical.to_string_lossy().into_owned()));
        self.settings.last_params = Some(canonical);
        self.remember_recent(path);
        if self
            .params
            .offer
            .as_ref()
            .is_some_and(|o| crate::frame::display_name(path) == format!("{}.json", o.name))
        {
            self.params.offer = None;
        }
        self.status = format!("opened parameters {}", path.display());
        Ok(())
    }

    /// Back to the built-in defaults (File ▸ Default parameters).
    pub(super) fn default_params(&mut self) {
        let p = RecognitionParams::default();
        self.set_recognition_params(p);
        self.params.loaded = p;
        self.params.path = None;
        self.params.try_run = None;
        self.settings.last_params = None;
        self.status = "default recognition parameters".to_owned();
    }

    fn set_recognition_params(&mut self, p: RecognitionParams) {
        let mut all = *self.pipeline.params();
        all.recognition = p;
        self.pipeline.set_params(all);
        self.reprocess();
    }

    /// Sets the value at `pointer` (a JSON pointer into the parameters: `/ball/diameter_cm`,
    /// `/ball/height_cm/0`), checked as a parameters file is.
    pub(super) fn set_param_value(&mut self, pointer: &str, value: Value) -> anyhow::Result<()> {
        let mut v = serde_json::to_value(self.recognition_params())?;
        let slot = v
            .pointer_mut(pointer)
            .with_context(|| format!("no parameter {pointer}"))?;
        *slot = value;
        let p = params_file::from_json(&v.to_string())
            .map_err(|e| anyhow::anyhow!("{}", e.at(Path::new("parameters"))))?;
        self.set_recognition_params(p);
        self.status = format!("parameter {pointer} changed");
        Ok(())
    }

    /// Resets the value at `pointer` to the one opened (or saved) last.
    pub(super) fn reset_param_value(&mut self, pointer: &str) -> anyhow::Result<()> {
        let loaded = serde_json::to_value(self.params.loaded)?;
        let value = loaded
            .pointer(pointer)
            .with_context(|| format!("no parameter {pointer}"))?
            .clone();
        self.set_param_value(pointer, value)
    }

    /// Every value back to the one opened (or saved) last.
    pub(super) fn reset_params(&mut self) {
        self.set_recognition_params(self.params.loaded);
        self.status = "parameters reset".to_owned();
    }

    /// Writes the parameters that differ from the defaults as a parameters file (atomically);
    /// it becomes the parameters' file.
    pub(super) fn save_params(&mut self, path: &Path) -> anyhow::Result<()> {
        let text =
            serde_json::to_string_pretty(&differences_from_defaults(self.recognition_params()))?;
        crate::atomic_file::write_atomic(path, format!("{text}\n").as_bytes())
            .with_context(|| format!("cannot save {}", path.display()))?;
        self.params.loaded = *self.recognition_params();
        self.params.path = Some(path.to_owned());
        let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned());
        self.remember_for_camera(|f| f.params = Some(canonical.to_string_lossy().into_owned()));
        self.settings.last_params = Some(canonical);
        self.remember_recent(path);
        self.status = format!("saved parameters {}", path.display());
        Ok(())
    }

    /// Starts the whole-stream check of the tuned parameters against the loaded ones.
    pub(super) fn try_params_on_stream(&mut self) -> anyhow::Result<()> {
        let total = self.source.as_ref().context("no stream open")?.len();
        anyhow::ensure!(
            self.params_modified(),
            "no parameter changed: tune one in the Parameters window first"
        );
        let mut before = *self.pipeline.params();
        before.recognition = self.params.loaded;
        self.params.try_run = Some(TryParams::new(
            self.pipeline.lut(),
            before,
            *self.pipeline.params(),
            total,
        ));
        self.settings.show_try_edit = true;
        Ok(())
    }

    /// Scans some frames of a running parameter check (from `tick`).
    pub(super) fn scan_try_params(&mut self, budget: Duration) {
        if let (Some(t), Some(src)) = (self.params.try_run.as_mut(), self.source.as_mut()) {
            t.scan(src, budget);
        }
    }

    /// After a stream opened: offers the parameter set it names unless that set is in use.
    pub(super) fn offer_param_set(&mut self, stream: &Path) {
        self.params.try_run = None;
        let name = crate::streams::StreamReader::open(stream)
            .ok()
            .and_then(|r| r.param_set().map(str::to_owned));
        self.params.offer = name.and_then(|name| {
            let in_use = self
                .params
                .path
                .as_deref()
                .is_some_and(|p| crate::frame::display_name(p) == format!("{name}.json"));
            (!in_use).then(|| ParamsOffer {
                path: find_param_set(&name, stream),
                name,
            })
        });
        if let Some(o) = &self.params.offer {
            let how = match &o.path {
                Some(p) => format!("{}: File > Use the stream's parameters", p.display()),
                None => format!("params/{}.json not found: File > Open parameters…", o.name),
            };
            self.status = format!(
                "{}; it is meant for the parameter set {} ({how})",
                self.status, o.name
            );
        }
    }
}
