//! The field view's cameras (issue 31 item 1): a session's cameras listed in the legend with
//! their colours and frames' states, each camera's coverage drawn, and the Camera coverage
//! switch hiding and showing the coverage (kittest, through the same workspace as the window).

use egui::epaint::Shape;
use egui_kittest::kittest::Queryable as _;
use eotn::app::field_cameras::coverage_fill;
use eotn::session::SslCameraId;
use eotn::workspace::{Command, Window, Workspace};

use crate::harness::{click_label, harness_with, workspace};

/// Every filled path's fill colour among `shapes`, nested shapes included.
fn fills(shapes: &[Shape], out: &mut Vec<egui::Color32>) {
    for s in shapes {
        match s {
            Shape::Path(p) if p.closed => out.push(p.fill),
            Shape::Vec(v) => fills(v, out),
            _ => {}
        }
    }
}

/// The cameras whose coverage fill the last frame drew.
fn coverage_drawn(h: &egui_kittest::Harness<'_, eotn::app::EotnApp>) -> Vec<u8> {
    let shapes: Vec<Shape> = h.output().shapes.iter().map(|c| c.shape.clone()).collect();
    let mut drawn = Vec::new();
    fills(&shapes, &mut drawn);
    (0..3u8)
        .filter(|k| drawn.contains(&coverage_fill(SslCameraId(*k))))
        .collect()
}

#[test]
fn the_field_view_lists_each_camera_and_its_switch_hides_and_shows_their_coverage() {
    let dir = tempfile::tempdir().unwrap();
    let session = crate::field::sim_field(dir.path(), 3, "320x200", 3, 6);
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![session])).unwrap();
    assert!(
        w.window_open(Window::FieldView),
        "a session shows the field view"
    );
    let mut h = harness_with(w);
    h.run();
    h.run();
    for k in 0..3 {
        assert!(
            h.query_by_label(&format!("camera {k}")).is_some(),
            "the legend lists camera {k}"
        );
    }
    assert_eq!(
        h.query_all_by_label("current").count(),
        3,
        "every camera's frame is in the first field frame"
    );
    assert_eq!(coverage_drawn(&h), [0, 1, 2]);
    click_label(&mut h, "Camera coverage");
    h.run();
    assert!(!workspace(&h).settings.overhead.coverage);
    assert_eq!(coverage_drawn(&h), Vec::<u8>::new(), "coverage hidden");
    assert!(h.query_by_label("camera 2").is_some(), "the legend stays");
    click_label(&mut h, "Camera coverage");
    h.run();
    assert!(workspace(&h).settings.overhead.coverage);
    assert_eq!(coverage_drawn(&h), [0, 1, 2], "coverage shown again");
}
