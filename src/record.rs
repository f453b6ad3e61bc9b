//! `ballpit --record OUT.gif --frames N`: the window as an animated GIF. After a short
//! warm-up, every frame is captured (Bevy's `Screenshot`), shrunk to at most
//! [`MAX_RECORD_WIDTH`] pixels wide, and kept; once all `N` have arrived they are encoded
//! ([`encode_gif`]) and the toy exits. While recording, each frame advances the game by
//! exactly [`RECORD_FRAME`] of time whatever the machine's speed, so the GIF plays at the
//! toy's real pace: 25 frames a second.
//!
//! At most [`MAX_RECORD_FRAMES`] frames, held in memory until encoded; the window cannot
//! be resized meanwhile, and closing it early is an error ([`RecordPlan::written`]).
//!
//! The encoder is pure and unit-tested: one palette, the recording's own colours if it has
//! at most 255, else 255 learnt from a few frames (NeuQuant), and after the first frame only the box of pixels that changed, with unchanged
//! pixels in it transparent, which is what keeps a few seconds of the toy small.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::time::TimeUpdateStrategy;

/// Game time each recorded frame advances.
pub const RECORD_FRAME: Duration = Duration::from_millis(40);
/// The GIF's frame delay, hundredths of a second: [`RECORD_FRAME`].
const DELAY_CENTISECONDS: u16 = 4;
/// The most frames one recording keeps (30 s; they are held in memory until encoded).
pub const MAX_RECORD_FRAMES: u32 = 750;
/// Frames recorded wider than this are shrunk by a whole factor to fit.
pub const MAX_RECORD_WIDTH: u32 = 800;
/// Frames run before recording starts (the window and panel settling).
const WARM_UP_FRAMES: u32 = 10;
/// Frames after the last request at which frames that never arrived count as failed.
const FRAMES_TO_GIVE_UP: u32 = 600;
/// The palette index that stands for "as in the previous frame".
const TRANSPARENT: u8 = 255;

/// An image as rows of RGBA bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbaFrame {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}

impl RgbaFrame {
    /// Each `factor` × `factor` block averaged into one pixel (edges that do not fill a
    /// block are dropped); opaque.
    pub fn shrink(&self, factor: u32) -> RgbaFrame {
        let factor = factor.max(1);
        let (width, height) = (self.width / factor, self.height / factor);
        let mut pixels = Vec::with_capacity((width * height * 4) as usize);
        let cells = f64::from(factor * factor);
        for y in 0..height {
            for x in 0..width {
                let mut sum = [0u32; 3];
                for dy in 0..factor {
                    let row = ((y * factor + dy) * self.width + x * factor) as usize * 4;
                    for pixel in self.pixels[row..row + factor as usize * 4].chunks_exact(4) {
                        for (total, &channel) in sum.iter_mut().zip(pixel) {
                            *total += u32::from(channel);
                        }
                    }
                }
                pixels.extend(sum.map(|total| (f64::from(total) / cells).round() as u8));
                pixels.push(255);
            }
        }
        RgbaFrame {
            width,
            height,
            pixels,
        }
    }
}

/// The smallest whole factor that brings `width` down to [`MAX_RECORD_WIDTH`] or less.
pub fn shrink_factor(width: u32) -> u32 {
    width.div_ceil(MAX_RECORD_WIDTH).max(1)
}

/// Encodes `frames` (all the same size) as a looping GIF with `delay_cs` hundredths of a
/// second per frame.
pub fn encode_gif(frames: &[RgbaFrame], delay_cs: u16) -> Result<Vec<u8>, String> {
    let first = frames.first().ok_or("no frames to encode")?;
    let (width, height) = (first.width, first.height);
    if width == 0 || height == 0 {
        return Err(format!("a {width} x {height} px frame has nothing to show"));
    }
    if frames
        .iter()
        .any(|f| (f.width, f.height) != (width, height))
    {
        return Err("the frames differ in size".into());
    }
    let too_large =
        |side: u32| u16::try_from(side).map_err(|_| format!("{side} px is too large for a GIF"));
    let (gif_width, gif_height) = (too_large(width)?, too_large(height)?);
    let palette = Palette::learn(frames);
    let colours = palette.colours();
    let mut out = Vec::new();
    {
        let mut encoder = gif::Encoder::new(&mut out, gif_width, gif_height, &colours)
            .map_err(|e| e.to_string())?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        let mut previous: Option<Vec<u8>> = None;
        for frame in frames {
            let indices: Vec<u8> = frame
                .pixels
                .chunks_exact(4)
                .map(|pixel| palette.index_of(pixel))
                .collect();
            let patch = changed_patch(&indices, previous.as_deref(), width);
            let Some(patch) = patch else {
                // Nothing changed: the previous frame simply stays a frame longer.
                let still = gif::Frame {
                    delay: delay_cs,
                    transparent: Some(TRANSPARENT),
                    width: 1,
                    height: 1,
                    buffer: vec![TRANSPARENT].into(),
                    ..default()
                };
                encoder.write_frame(&still).map_err(|e| e.to_string())?;
                continue;
            };
            let gif_frame = gif::Frame {
                delay: delay_cs,
                transparent: previous.as_ref().map(|_| TRANSPARENT),
                left: patch.left as u16,
                top: patch.top as u16,
                width: patch.width as u16,
                height: patch.height as u16,
                buffer: patch.buffer.into(),
                ..default()
            };
            encoder.write_frame(&gif_frame).map_err(|e| e.to_string())?;
            previous = Some(indices);
        }
    }
    Ok(out)
}

/// The recording's colours: exactly its own when it has at most 255, otherwise 255 learnt
/// by NeuQuant from up to four frames spread over it. The 256th index is [`TRANSPARENT`].
enum Palette {
    Exact(HashMap<[u8; 3], u8>),
    Learnt(color_quant::NeuQuant),
}

/// Pixels below which NeuQuant learns from every one of them rather than a sample.
const SMALL_SAMPLE: usize = 1 << 20;

impl Palette {
    fn learn(frames: &[RgbaFrame]) -> Palette {
        let mut exact = HashMap::new();
        let colours = frames.iter().flat_map(|frame| frame.pixels.chunks_exact(4));
        for pixel in colours {
            let colour = [pixel[0], pixel[1], pixel[2]];
            let next = exact.len();
            if next == usize::from(TRANSPARENT) && !exact.contains_key(&colour) {
                let step = frames.len().div_ceil(4).max(1);
                let sample: Vec<u8> = (frames.iter().step_by(step))
                    .flat_map(|frame| frame.pixels.iter().copied())
                    .collect();
                let sample_factor = if sample.len() / 4 < SMALL_SAMPLE {
                    1
                } else {
                    10
                };
                return Palette::Learnt(color_quant::NeuQuant::new(sample_factor, 255, &sample));
            }
            exact.entry(colour).or_insert(next as u8);
        }
        Palette::Exact(exact)
    }

    /// The 256 colours, RGB.
    fn colours(&self) -> Vec<u8> {
        let mut colours = match self {
            Palette::Exact(exact) => {
                let mut colours = vec![0; exact.len() * 3];
                for (colour, &index) in exact {
                    colours[usize::from(index) * 3..][..3].copy_from_slice(colour);
                }
                colours
            }
            Palette::Learnt(quantizer) => quantizer.color_map_rgb(),
        };
        colours.resize(256 * 3, 0);
        colours
    }

    fn index_of(&self, pixel: &[u8]) -> u8 {
        match self {
            Palette::Exact(exact) => exact[&[pixel[0], pixel[1], pixel[2]]],
            Palette::Learnt(quantizer) => quantizer.index_of(pixel) as u8,
        }
    }
}

/// The part of a frame written to the GIF.
#[derive(Debug, PartialEq)]
struct Patch {
    left: u32,
    top: u32,
    width: u32,
    height: u32,
    buffer: Vec<u8>,
}

/// The box of `indices` that differs from `previous` (the whole frame if there is none),
/// with unchanged pixels inside it [`TRANSPARENT`]; `None` if nothing changed.
fn changed_patch(indices: &[u8], previous: Option<&[u8]>, width: u32) -> Option<Patch> {
    if width == 0 {
        return None;
    }
    let height = indices.len() as u32 / width;
    let Some(previous) = previous else {
        return Some(Patch {
            left: 0,
            top: 0,
            width,
            height,
            buffer: indices.to_vec(),
        });
    };
    let (mut low, mut high) = ((u32::MAX, u32::MAX), (0, 0));
    for (index, _) in (indices.iter().zip(previous).enumerate()).filter(|(_, (a, b))| a != b) {
        let (x, y) = (index as u32 % width, index as u32 / width);
        (low, high) = ((low.0.min(x), low.1.min(y)), (high.0.max(x), high.1.max(y)));
    }
    if low.0 == u32::MAX {
        return None;
    }
    let mut buffer = Vec::with_capacity(((high.0 - low.0 + 1) * (high.1 - low.1 + 1)) as usize);
    for y in low.1..=high.1 {
        let row = (y * width) as usize;
        let span = row + low.0 as usize..=row + high.0 as usize;
        buffer.extend(
            (indices[span.clone()].iter().zip(&previous[span]))
                .map(|(&now, &before)| if now == before { TRANSPARENT } else { now }),
        );
    }
    Some(Patch {
        left: low.0,
        top: low.1,
        width: high.0 - low.0 + 1,
        height: high.1 - low.1 + 1,
        buffer,
    })
}

/// What `--record` asked for, and the frames captured so far (filled by the screenshots'
/// observers as they arrive, in request order).
#[derive(Resource)]
pub struct RecordPlan {
    pub path: PathBuf,
    pub frames: u32,
    captured: Arc<Mutex<Vec<Option<RgbaFrame>>>>,
    requested: u32,
    last_request: u32,
    /// Set once the GIF is written: a window closed before then recorded nothing.
    pub written: Arc<AtomicBool>,
    /// Encoded (or failed): the toy is on its way out.
    finished: bool,
}

impl RecordPlan {
    pub fn new(path: PathBuf, frames: u32) -> Self {
        Self {
            path,
            frames,
            captured: Arc::new(Mutex::new(vec![None; frames as usize])),
            requested: 0,
            last_request: 0,
            written: Arc::new(AtomicBool::new(false)),
            finished: false,
        }
    }
}

/// Records the window into `plan.path` and exits (see the module header). Returns the flag
/// that says whether the GIF was written.
pub fn start_recording(app: &mut App, plan: RecordPlan) -> Arc<AtomicBool> {
    let written = plan.written.clone();
    app.insert_resource(plan)
        .insert_resource(TimeUpdateStrategy::ManualDuration(RECORD_FRAME))
        .add_systems(Update, record_and_exit);
    written
}

fn record_and_exit(
    mut plan: ResMut<RecordPlan>,
    mut frame: Local<u32>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    *frame += 1;
    if *frame > WARM_UP_FRAMES && plan.requested < plan.frames {
        let (slot, captured) = (plan.requested as usize, plan.captured.clone());
        commands.spawn(Screenshot::primary_window()).observe(
            move |screenshot: On<ScreenshotCaptured>| {
                let image = match screenshot.image.clone().try_into_dynamic() {
                    Ok(image) => image,
                    Err(error) => {
                        error!("recorded frame {slot} cannot be read: {error}");
                        return;
                    }
                };
                let image = image.to_rgba8();
                let frame = RgbaFrame {
                    width: image.width(),
                    height: image.height(),
                    pixels: image.into_raw(),
                };
                let shrunk = frame.shrink(shrink_factor(frame.width));
                if let Ok(mut captured) = captured.lock() {
                    captured[slot] = Some(shrunk);
                }
            },
        );
        plan.requested += 1;
        plan.last_request = *frame;
        return;
    }
    if plan.requested < plan.frames || plan.finished {
        return;
    }
    let frames = match plan.captured.lock() {
        Ok(mut captured) if captured.iter().all(Option::is_some) => Some(
            std::mem::take(&mut *captured)
                .into_iter()
                .flatten()
                .collect::<Vec<_>>(),
        ),
        _ => None,
    };
    match frames {
        Some(frames) => {
            let written = encode_gif(&frames, DELAY_CENTISECONDS)
                .and_then(|gif| std::fs::write(&plan.path, gif).map_err(|e| e.to_string()));
            match written {
                Ok(()) => {
                    plan.written.store(true, Ordering::Release);
                    info!(
                        "recorded {} frames to {}",
                        frames.len(),
                        plan.path.display()
                    );
                    exit.write(AppExit::Success);
                }
                Err(e) => {
                    error!("{}: cannot write the recording: {e}", plan.path.display());
                    exit.write(AppExit::error());
                }
            }
            plan.finished = true;
        }
        None if *frame >= plan.last_request + FRAMES_TO_GIVE_UP => {
            error!("the recording {} lost frames", plan.path.display());
            exit.write(AppExit::error());
        }
        None => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `width` × `height` frame of `background` with a `square`-coloured 2 × 2 square at
    /// `x`, `y`.
    fn frame_with_square(x: u32, y: u32) -> RgbaFrame {
        let (width, height) = (12, 8);
        let mut pixels = Vec::new();
        for row in 0..height {
            for column in 0..width {
                let inside = (x..x + 2).contains(&column) && (y..y + 2).contains(&row);
                pixels.extend(if inside {
                    [230, 60, 40, 255]
                } else {
                    [20, 24, 32, 255]
                });
            }
        }
        RgbaFrame {
            width,
            height,
            pixels,
        }
    }

    /// Decodes `gif` frame by frame onto a canvas, as a viewer does.
    fn play(gif: &[u8]) -> Vec<(u16, Vec<u8>)> {
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(gif).unwrap();
        let (width, height) = (decoder.width() as usize, decoder.height() as usize);
        let mut canvas = vec![0u8; width * height * 4];
        let mut shown = Vec::new();
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            for (index, pixel) in frame.buffer.chunks_exact(4).enumerate() {
                let (x, y) = (
                    frame.left as usize + index % frame.width as usize,
                    frame.top as usize + index / frame.width as usize,
                );
                if pixel[3] != 0 {
                    canvas[(y * width + x) * 4..][..4].copy_from_slice(pixel);
                }
            }
            shown.push((frame.delay, canvas.clone()));
        }
        shown
    }

    #[test]
    fn a_moving_square_plays_back_as_recorded_with_only_the_changes_stored() {
        let frames = [
            frame_with_square(1, 1),
            frame_with_square(4, 2),
            frame_with_square(4, 2),
            frame_with_square(9, 5),
        ];
        let gif = encode_gif(&frames, 4).unwrap();
        let shown = play(&gif);
        assert_eq!(shown.len(), 4);
        for ((delay, canvas), frame) in shown.iter().zip(&frames) {
            assert_eq!(*delay, 4);
            assert_eq!(canvas, &frame.pixels);
        }
        let indices = |frame: &RgbaFrame| -> Vec<u8> {
            frame
                .pixels
                .chunks_exact(4)
                .map(|p| u8::from(p[0] > 100))
                .collect()
        };
        let patch = changed_patch(&indices(&frames[1]), Some(&indices(&frames[0])), 12).unwrap();
        assert_eq!(
            (patch.left, patch.top, patch.width, patch.height),
            (1, 1, 5, 3)
        );
        assert_eq!(
            changed_patch(&indices(&frames[2]), Some(&indices(&frames[1])), 12),
            None
        );
    }

    #[test]
    fn a_recording_of_more_than_255_colours_plays_back_close_to_them() {
        let gradient = |shift: u32| RgbaFrame {
            width: 40,
            height: 20,
            pixels: (0..800u32)
                .flat_map(|i| {
                    [
                        (i * 7 + shift) as u8,
                        (i / 3) as u8,
                        (i % 40 * 6) as u8,
                        255,
                    ]
                })
                .collect(),
        };
        let frames = [gradient(0), gradient(0), gradient(9)];
        let shown = play(&encode_gif(&frames, 4).unwrap());
        assert_eq!(shown.len(), 3);
        for ((_, canvas), frame) in shown.iter().zip(&frames) {
            let errors: Vec<u8> = (canvas.iter().zip(&frame.pixels))
                .map(|(a, b)| a.abs_diff(*b))
                .collect();
            let mean = errors.iter().map(|&e| f64::from(e)).sum::<f64>() / errors.len() as f64;
            let worst = errors.iter().max().unwrap();
            assert!(
                mean <= 12.0 && *worst <= 64,
                "mean error {mean}, worst {worst}"
            );
        }
    }

    #[test]
    fn shrinking_averages_blocks_and_fits_the_width() {
        let frame = RgbaFrame {
            width: 2,
            height: 2,
            pixels: vec![0, 0, 0, 255, 100, 0, 0, 255, 0, 200, 0, 255, 0, 0, 40, 255],
        };
        assert_eq!(frame.shrink(2).pixels, vec![25, 50, 10, 255]);
        assert_eq!(shrink_factor(800), 1);
        assert_eq!(shrink_factor(1500), 2);
        assert_eq!(shrink_factor(2500), 4);
        assert!(encode_gif(&[], 4).is_err());
    }
}
