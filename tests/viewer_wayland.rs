//! `fovea view` on Wayland: a headless Weston compositor (its headless backend, shared-memory
//! buffers, which lavapipe's Wayland WSI presents through), no X server in reach. The same
//! check as on X11: one frame equals `fovea render` bit for bit, and a resize mid-run is clean
//! (validation layer on).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// A headless Weston on its own socket in its own runtime directory; killed on drop.
struct Weston {
    child: Child,
    runtime_dir: PathBuf,
    socket: String,
}

impl Weston {
    fn start(dir: &Path) -> Self {
        let runtime_dir = dir.join("xdg-runtime");
        std::fs::create_dir_all(&runtime_dir).unwrap();
        // Wayland refuses runtime directories others can read.
        std::fs::set_permissions(
            &runtime_dir,
            std::os::unix::fs::PermissionsExt::from_mode(0o700),
        )
        .unwrap();
        let socket = format!("fovea-test-{}", std::process::id());
        let mut child = Command::new("weston")
            .args([
                "--backend=headless-backend.so",
                &format!("--socket={socket}"),
                "--idle-time=0",
            ])
            .env("XDG_RUNTIME_DIR", &runtime_dir)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect(
                "weston is needed for the Wayland viewer test: run tools/setup.sh (package weston)",
            );
        let path = runtime_dir.join(&socket);
        // Until the socket is there, or weston has given up (no clock decides: a slow
        // machine only waits longer).
        while !path.exists() {
            if let Some(status) = child.try_wait().unwrap() {
                panic!(
                    "weston exited ({status}) without opening {}",
                    path.display()
                );
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        Self {
            child,
            runtime_dir,
            socket,
        }
    }
}

impl Drop for Weston {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn on_wayland_one_frame_equals_render_and_a_resize_is_clean() {
    let dir = common::test_dir("wayland");
    let weston = Weston::start(&dir);
    let view = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_fovea"))
            .arg("view")
            // One frame of a running mean is the rendered frame itself (the default, the
            // temporal history, traces with its lattice shift).
            .args(["--refine", "foveated"])
            .args(args)
            .current_dir(&dir)
            .env("XDG_RUNTIME_DIR", &weston.runtime_dir)
            .env("WAYLAND_DISPLAY", &weston.socket)
            .env_remove("DISPLAY")
            .env("FOVEA_VALIDATION", "1")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string()
            + &String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "fovea view {args:?}:\n{text}");
        assert!(!text.contains("validation"), "fovea view {args:?}:\n{text}");
        text
    };
    let shot = dir.join("view.png");
    let shared = ["--scene", "cornell", "--foveation", "thesis", "--seed", "3"];
    let size = ["--width", "64", "--height", "48", "--gaze", "30,20"];
    view(
        &[
            &size[..],
            &shared[..],
            &["--frames", "1", "--screenshot", shot.to_str().unwrap()],
        ]
        .concat(),
    );
    let rendered = dir.join("render.png");
    let (ok, out) = common::fovea(
        &[
            &["render"][..],
            &size[..],
            &shared[..],
            &["--out", rendered.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(ok, "{out}");
    assert!(
        std::fs::read(&shot).unwrap() == std::fs::read(&rendered).unwrap(),
        "on Wayland the viewer's PNG differs from fovea render's"
    );
    // A resize mid-run recreates the swapchain; the run ends at the new size.
    let script = dir.join("script.txt");
    std::fs::write(&script, "1 resize 80 40\n").unwrap();
    let text = view(
        &[
            &size[..],
            &shared[..],
            &["--frames", "4", "--script", script.to_str().unwrap()],
        ]
        .concat(),
    );
    // Created once at the start, once more for the resize.
    assert!(text.contains("swapchain recreated 2 times"), "{text}");
}
