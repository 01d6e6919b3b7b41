//! Several overhead cameras on one field (issue 31): the simulated rig, its session, the
//! benchmark and the merged detections.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use eotn::model::GroundTruth;
use eotn::session::{CameraId, Session, SessionSource};

use crate::common::{eotn, eotn_ok};

/// `eotn overhead sim-field` of `cameras` small cameras into `dir`: its `SESSION.json`.
pub fn sim_field(dir: &Path, cameras: usize, size: &str, frames: usize, seed: u64) -> PathBuf {
    let (c, f, s) = (cameras.to_string(), frames.to_string(), seed.to_string());
    eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("sim-field"),
        OsStr::new("--cameras"),
        OsStr::new(&c),
        OsStr::new("--size"),
        OsStr::new(size),
        OsStr::new("--frames"),
        OsStr::new(&f),
        OsStr::new("--seed"),
        OsStr::new(&s),
        OsStr::new("-o"),
        dir.as_os_str(),
    ]);
    dir.join("SESSION.json")
}

#[test]
fn the_simulated_field_is_a_session_of_cameras_with_their_own_tables_calibrations_and_truth() {
    let dir = tempfile::tempdir().unwrap();
    let path = sim_field(dir.path(), 2, "320x200", 3, 6);
    let session = Session::load(&path).unwrap();
    assert_eq!(session.overhead.len(), 2);
    let mut cameras = Vec::new();
    for (k, cam) in session.overhead.iter().enumerate() {
        assert_eq!(cam.id, CameraId(u8::try_from(k).unwrap()));
        let SessionSource::Recording(p) = &cam.source else {
            panic!("a recording expected");
        };
        let mut reader = eotn::streams::StreamReader::open(p).unwrap();
        assert_eq!(reader.len(), 3);
        let record = reader.read(2).unwrap();
        assert_eq!((record.frame.width(), record.frame.height()), (320, 200));
        let truth = serde_json::from_value::<GroundTruth>(record.ground_truth.unwrap()).unwrap();
        let GroundTruth::Overhead(t) = truth else {
            panic!("overhead truth expected");
        };
        assert!(t.robots.len() >= 4);
        let cal = eotn::overhead::Calibration::load(&cam.calibration).unwrap();
        // The solved camera is close to the true one.
        let d = t.camera.pose.position_cm[0] - cal.camera.pose.position_cm[0];
        assert!(d.abs() < 10.0, "camera {k}: {d} cm off in x");
        assert!(eotn::lut::LookupTable::load(&cam.lut).is_ok());
        cameras.push(t.camera);
    }
    assert_ne!(cameras[0], cameras[1]);
}

#[test]
fn a_rig_camera_beyond_1920x1200_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = eotn(&[
        OsStr::new("overhead"),
        OsStr::new("sim-field"),
        OsStr::new("--size"),
        OsStr::new("2000x1200"),
        OsStr::new("-o"),
        dir.path().as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("1920x1200"), "{err}");
}
