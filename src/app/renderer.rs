//! Which renderer draws the window: wgpu where it finds a real GPU, OpenGL (glow) where it finds
//! only a software adapter or none.
//!
//! Why: on a machine without a GPU driver (a virtual machine, a remote desktop, a laptop whose
//! driver is not set up) wgpu falls back to Mesa's software Vulkan (lavapipe), which costs
//! 40–110 ms per UI frame at 1280×800, while the same frame through OpenGL on Mesa's llvmpipe
//! costs about a fifth of that (docs/renderer.md). The choice is made before the window opens by
//! asking wgpu which adapters it has; `eotn open --renderer` and a saved setting override it.

use std::path::PathBuf;

use crate::app_options::RendererSetting;

/// The renderer that draws the window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RendererKind {
    /// wgpu (Vulkan, Metal, DX12 or GL through wgpu).
    Wgpu,
    /// eframe's OpenGL renderer (glow).
    Gl,
}

impl RendererKind {
    /// Its name in the status bar and the About window.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Wgpu => "wgpu",
            Self::Gl => "OpenGL",
        }
    }

    /// The other one, tried when this one cannot start.
    #[must_use]
    pub const fn other(self) -> Self {
        match self {
            Self::Wgpu => Self::Gl,
            Self::Gl => Self::Wgpu,
        }
    }

    /// eframe's renderer.
    #[must_use]
    pub const fn eframe(self) -> eframe::Renderer {
        match self {
            Self::Wgpu => eframe::Renderer::Wgpu,
            Self::Gl => eframe::Renderer::Glow,
        }
    }
}

/// One adapter wgpu offers, as far as the choice cares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AdapterSummary {
    /// The adapter's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)", "NVIDIA GeForce …").
    pub name: String,
    /// The backend (Vulkan, Gl, …), as wgpu names it.
    pub backend: String,
    /// Whether it is a CPU/software rasteriser rather than a GPU.
    pub software: bool,
}

impl AdapterSummary {
    /// From wgpu's description of an adapter.
    #[must_use]
    pub fn from_info(info: &egui_wgpu::wgpu::AdapterInfo) -> Self {
        Self {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            software: info.device_type == egui_wgpu::wgpu::DeviceType::Cpu
                || is_software_name(&info.name),
        }
    }
}

/// Names of the software rasterisers that report themselves as something other than a CPU
/// device (lavapipe says "llvmpipe"; SwiftShader, WARP and softpipe say their names).
#[must_use]
pub fn is_software_name(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    [
        "llvmpipe",
        "lavapipe",
        "softpipe",
        "swiftshader",
        "microsoft basic render",
        "warp",
    ]
    .iter()
    .any(|s| n.contains(s))
}

/// What was chosen and why, for the status bar and the About window.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RendererChoice {
    /// The renderer to start.
    pub kind: RendererKind,
    /// Why, in a few words ("only software adapters: llvmpipe …", "--renderer gl", …).
    pub reason: String,
}

/// The rule of `--renderer auto`: wgpu when some adapter is a GPU, OpenGL when every adapter is a
/// software rasteriser or there is none.
#[must_use]
pub fn auto_choice(adapters: &[AdapterSummary]) -> RendererChoice {
    if let Some(gpu) = adapters.iter().find(|a| !a.software) {
        return RendererChoice {
            kind: RendererKind::Wgpu,
            reason: format!("GPU found: {} ({})", gpu.name, gpu.backend),
        };
    }
    let reason = if adapters.is_empty() {
        "wgpu found no adapter".to_owned()
    } else {
        let names: Vec<String> = adapters
            .iter()
            .map(|a| format!("{} ({})", a.name, a.backend))
            .collect();
        format!("only software adapters: {}", names.join(", "))
    };
    RendererChoice {
        kind: RendererKind::Gl,
        reason,
    }
}

/// The renderer for `setting` (from `--renderer`, else the saved one, else auto).
#[must_use]
pub fn choose(setting: RendererSetting) -> RendererChoice {
    match setting {
        RendererSetting::Wgpu => RendererChoice {
            kind: RendererKind::Wgpu,
            reason: "chosen in the settings (--renderer wgpu)".to_owned(),
        },
        RendererSetting::Gl => RendererChoice {
            kind: RendererKind::Gl,
            reason: "chosen in the settings (--renderer gl)".to_owned(),
        },
        RendererSetting::Auto => auto_choice(&wgpu_adapters()),
    }
}

/// The adapters wgpu finds on the Vulkan, Metal, DX12 and GL backends (a tenth of a second).
#[must_use]
pub fn wgpu_adapters() -> Vec<AdapterSummary> {
    use egui_wgpu::wgpu;
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::all(),
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
        .iter()
        .map(|a| AdapterSummary::from_info(&a.get_info()))
        .collect()
}

/// Where the saved renderer setting lives: `renderer.txt` in eframe's storage folder.
fn setting_path() -> Option<PathBuf> {
    eframe::storage_dir("eotn").map(|d| d.join("renderer.txt"))
}

/// The saved renderer setting (auto when none or unreadable).
#[must_use]
pub fn saved_setting() -> RendererSetting {
    setting_path()
        .and_then(|p| crate::input_file::read_text_bounded(&p, 1024, "a renderer setting").ok())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(RendererSetting::Auto)
}

/// Saves the renderer setting for the next start.
///
/// # Errors
/// The folder or file cannot be written.
pub fn save_setting(setting: RendererSetting) -> anyhow::Result<()> {
    let Some(path) = setting_path() else {
        anyhow::bail!("no storage folder for settings");
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    crate::atomic_file::write_atomic(&path, setting.name().as_bytes())?;
    Ok(())
}

/// What the running renderer says it is: the wgpu adapter, or GL's renderer and version strings.
#[must_use]
pub fn live_adapter(cc: &eframe::CreationContext<'_>) -> String {
    if let Some(rs) = &cc.wgpu_render_state {
        let info = rs.adapter.get_info();
        return format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type);
    }
    if let Some(gl) = &cc.gl {
        return gl_renderer_string(gl);
    }
    "unknown".to_owned()
}

/// `GL_RENDERER (OpenGL GL_VERSION)` of the window's context.
#[expect(
    unsafe_code,
    reason = "glGetString is unsafe in glow; the one GL call eotn makes itself"
)]
fn gl_renderer_string(gl: &eframe::glow::Context) -> String {
    use eframe::glow::HasContext as _;
    // SAFETY: eframe made this context current on this (the main) thread before creating the
    // app, and glGetString with RENDERER or VERSION only reads driver-owned strings.
    let (renderer, version) = unsafe {
        (
            gl.get_parameter_string(eframe::glow::RENDERER),
            gl.get_parameter_string(eframe::glow::VERSION),
        )
    };
    format!("{renderer} (OpenGL {version})")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adapter(name: &str, software: bool) -> AdapterSummary {
        AdapterSummary {
            name: name.into(),
            backend: "Vulkan".into(),
            software,
        }
    }

    #[test]
    fn auto_takes_wgpu_when_any_adapter_is_a_gpu() {
        let c = auto_choice(&[
            adapter("llvmpipe (LLVM 15)", true),
            adapter("AMD Radeon", false),
        ]);
        assert_eq!(c.kind, RendererKind::Wgpu);
        assert!(c.reason.contains("AMD Radeon"), "{}", c.reason);
    }

    #[test]
    fn auto_takes_gl_when_only_software_adapters_or_none_exist() {
        assert_eq!(
            auto_choice(&[adapter("llvmpipe (LLVM 15)", true)]).kind,
            RendererKind::Gl
        );
        let none = auto_choice(&[]);
        assert_eq!(none.kind, RendererKind::Gl);
        assert!(none.reason.contains("no adapter"));
    }

    #[test]
    fn software_rasterisers_are_known_by_name_whatever_their_device_type() {
        for n in [
            "llvmpipe (LLVM 15.0.6, 256 bits)",
            "SwiftShader Device (Subzero)",
            "Microsoft Basic Render Driver",
            "softpipe",
        ] {
            assert!(is_software_name(n), "{n}");
        }
        assert!(!is_software_name("NVIDIA GeForce RTX 3060"));
        assert!(!is_software_name("Intel(R) UHD Graphics 620 (KBL GT2)"));
    }

    #[test]
    fn a_forced_setting_wins_over_the_adapters() {
        assert_eq!(choose(RendererSetting::Gl).kind, RendererKind::Gl);
        assert_eq!(choose(RendererSetting::Wgpu).kind, RendererKind::Wgpu);
    }
}
