//! What the video tests share: a simulated scene rendered into a Y4M file.

use eenf_sim::{render_video, CameraConfig, MainsPhase, SimConfig};
use eenf_video::Y4mWriter;

/// Renders `config`'s scene through `camera` under `mains` into a temporary Y4M file.
pub fn write_y4m(
    config: &SimConfig,
    camera: &CameraConfig,
    mains: &MainsPhase,
) -> tempfile::TempPath {
    let file = tempfile::Builder::new().suffix(".y4m").tempfile().unwrap();
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut out =
        Y4mWriter::new(std::io::BufWriter::new(file.as_file()), w, h, camera.fps).unwrap();
    render_video(config, camera, mains, |frame| out.write_frame(frame)).unwrap();
    drop(out);
    file.into_temp_path()
}
