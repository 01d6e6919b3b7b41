//! The renderer's floor: an eframe window at the app's size (1280×800) that draws next to
//! nothing and repaints continuously, printing the median frame interval and eframe's CPU time
//! per frame after `EOTN_FLOOR_SECONDS` (default 10). Run it where the app runs (e.g. under Xvfb
//! with Mesa's software Vulkan) to see how much of the app's frame time is the renderer's alone:
//!
//!     cargo run --release --example egui_floor --features gui
//!
//! With `EOTN_FLOOR_IMAGE=1` it also draws one 640×480 texture scaled to fill the window, as the
//! app's enlarged view does (`EOTN_FLOOR_IMAGE=2`: that texture twice, the second blended at half
//! opacity, as the app's classified layer over the frame); `EOTN_FLOOR_DITHER=0` turns egui's
//! dithering off; `EOTN_FLOOR_RENDERER=gl` draws with OpenGL (glow) instead of wgpu;
//! `EOTN_FLOOR_PRESENT=immediate|mailbox|fifo` picks the present mode (default: eframe's).

use std::time::{Duration, Instant};

struct Floor {
    done: bool,
    start: Instant,
    last: Option<Instant>,
    intervals_ms: Vec<f64>,
    cpu_ms: Vec<f64>,
    run_for: Duration,
    texture: Option<egui::TextureHandle>,
    /// How many times the texture is drawn over the window (0: none).
    image_layers: u8,
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

impl eframe::App for Floor {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let now = Instant::now();
        if let Some(t) = self.last {
            self.intervals_ms.push((now - t).as_secs_f64() * 1e3);
        }
        if let Some(c) = frame.info().cpu_usage {
            self.cpu_ms.push(f64::from(c) * 1e3);
        }
        self.last = Some(now);
        let ctx = ui.ctx().clone();
        if self.image_layers > 0 && self.texture.is_none() {
            let img = egui::ColorImage::new(
                [640, 480],
                (0..640 * 480)
                    .map(|i| egui::Color32::from_gray((i % 251) as u8))
                    .collect(),
            );
            self.texture = Some(ctx.load_texture("floor", img, egui::TextureOptions::NEAREST));
        }
        egui::CentralPanel::default().show(ui, |ui| {
            if let Some(t) = &self.texture {
                let rect = ui.max_rect();
                let uv = egui::Rect::from_min_max(egui::Pos2::ZERO, egui::pos2(1.0, 1.0));
                for layer in 0..self.image_layers {
                    let tint = if layer == 0 {
                        egui::Color32::WHITE
                    } else {
                        egui::Color32::from_white_alpha(128)
                    };
                    ui.painter().image(t.id(), rect, uv, tint);
                }
            }
            ui.label(format!("frame {}", self.intervals_ms.len()));
        });
        if now - self.start > self.run_for && !self.done {
            self.done = true;
            println!(
                "egui floor at {:?}: {} frames, median interval {:.2} ms, median eframe CPU {:.2} ms{}",
                ctx.content_rect().size(),
                self.intervals_ms.len(),
                median(&mut self.intervals_ms),
                median(&mut self.cpu_ms),
                match self.image_layers {
                    0 => String::new(),
                    n => format!(" (with a full-window 640×480 texture drawn {n} times)"),
                }
            );
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        ctx.request_repaint();
    }
}

fn main() -> eframe::Result {
    let secs = std::env::var("EOTN_FLOOR_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10.0);
    let mut options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default().with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    if std::env::var("EOTN_FLOOR_DITHER").is_ok_and(|v| v == "0") {
        options.dithering = false;
    }
    if std::env::var("EOTN_FLOOR_RENDERER").is_ok_and(|v| v == "gl") {
        options.renderer = eframe::Renderer::Glow;
    }
    match std::env::var("EOTN_FLOOR_PRESENT").as_deref() {
        Ok("immediate") => {
            options.wgpu_options.surface.present_mode = eframe::wgpu::PresentMode::AutoNoVsync;
        }
        Ok("mailbox") => {
            options.wgpu_options.surface.present_mode = eframe::wgpu::PresentMode::Mailbox
        }
        Ok("fifo") => options.wgpu_options.surface.present_mode = eframe::wgpu::PresentMode::Fifo,
        _ => {}
    }
    eframe::run_native(
        "egui floor",
        options,
        Box::new(move |_| {
            Ok(Box::new(Floor {
                done: false,
                start: Instant::now(),
                last: None,
                intervals_ms: Vec::new(),
                cpu_ms: Vec::new(),
                run_for: Duration::from_secs_f64(secs),
                texture: None,
                image_layers: match std::env::var("EOTN_FLOOR_IMAGE").as_deref() {
                    Err(_) | Ok("0") => 0,
                    Ok("2") => 2,
                    Ok(_) => 1,
                },
            }))
        }),
    )
}
