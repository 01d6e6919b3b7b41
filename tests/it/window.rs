//! The real window under a virtual X server (Xvfb): the OpenGL path starts, draws the sample and
//! closes by itself (`--quit-after`), as a user without a GPU would run it. The kittest snapshot
//! tests keep drawing through wgpu (lavapipe).

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// An Xvfb display of our own, ended when dropped.
struct VirtualDisplay {
    server: Child,
    name: String,
}

impl VirtualDisplay {
    /// Starts `Xvfb :N` on the first free N from 140, or `None` (skipped outside CI, failed in
    /// CI) when Xvfb is not installed.
    fn start() -> Option<Self> {
        let have = Command::new("sh")
            .args([
                "-c",
                "command -v Xvfb && command -v xwd && command -v convert",
            ])
            .output()
            .is_ok_and(|o| o.status.success());
        if !have {
            crate::common::skipped(
                "Xvfb, xwd or ImageMagick's convert not installed; the real-window test did not run",
                "scripts/deps.sh installs xvfb, x11-apps and imagemagick",
            );
            return None;
        }
        let n = (140..400)
            .find(|n| {
                !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
                    && !Path::new(&format!("/tmp/.X{n}-lock")).exists()
            })
            .expect("a free display number");
        let name = format!(":{n}");
        let server = Command::new("Xvfb")
            .args([
                name.as_str(),
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts");
        let socket = PathBuf::from(format!("/tmp/.X11-unix/X{n}"));
        let t0 = Instant::now();
        while !socket.exists() && t0.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(50));
        }
        assert!(socket.exists(), "Xvfb {name} did not start");
        Some(Self { server, name })
    }

    /// The whole screen as packed RGB, 1280×800.
    fn screenshot(&self) -> image::RgbImage {
        let dir = tempfile::tempdir().unwrap();
        let xwd = dir.path().join("shot.xwd");
        let png = dir.path().join("shot.png");
        let ok = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "xwd -root -silent -display {} > {} && convert xwd:{} png:{}",
                self.name,
                xwd.display(),
                xwd.display(),
                png.display()
            ))
            .status()
            .expect("xwd and convert run");
        assert!(ok.success(), "the screenshot failed");
        image::open(&png).expect("a PNG screenshot").to_rgb8()
    }
}

impl Drop for VirtualDisplay {
    fn drop(&mut self) {
        let _ = self.server.kill();
        let _ = self.server.wait();
    }
}

#[test]
fn the_gl_window_starts_draws_the_sample_and_closes_by_itself() {
    let Some(display) = VirtualDisplay::start() else {
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let home = tempfile::tempdir().unwrap();
    let mut app = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .args(["open", "--renderer", "gl", "--quit-after", "20"])
        .arg(root.join("streams/sample.mcap"))
        .arg(root.join("lookup_tables/sample.lut"))
        .env("DISPLAY", &display.name)
        .env_remove("WAYLAND_DISPLAY")
        .env("HOME", home.path())
        .env("XDG_DATA_HOME", home.path().join("data"))
        .env("XDG_CONFIG_HOME", home.path().join("config"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the app starts");
    // The app says what draws it once the window exists; give the software rasteriser time to
    // draw a few frames, then look at the screen.
    std::thread::sleep(Duration::from_secs(8));
    let shot = display.screenshot();
    let green = shot
        .pixels()
        .filter(|p| p[1] > 100 && p[1] > p[0].saturating_add(30) && p[1] > p[2].saturating_add(30))
        .count();
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = app.try_wait().unwrap() {
            break s;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "the window did not close after --quit-after"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut stderr = String::new();
    app.stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    assert!(status.success(), "eotn open exited with {status}: {stderr}");
    assert!(
        stderr.contains("drawing with OpenGL"),
        "the GL renderer did not draw the window: {stderr}"
    );
    // The sample's field is green; a blank or black window has none.
    assert!(
        green > 20_000,
        "only {green} green pixels on the screen: the sample was not drawn ({stderr})"
    );
    // The choice was saved for the next start.
    let saved = std::fs::read_to_string(home.path().join("data/eotn/renderer.txt"));
    assert_eq!(saved.ok().as_deref(), Some("gl"));
}
