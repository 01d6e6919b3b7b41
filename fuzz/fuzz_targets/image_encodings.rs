//! Raw image encodings (every one eotn reads, any size and step) and compressed images (JPEG,
//! PNG) from message bytes. The first 8 bytes choose width, height, step and encoding.
#![no_main]

use eotn::frame::{PixelEncoding, RawImage, decode_compressed, decode_raw};
use libfuzzer_sys::fuzz_target;

const NAMES: [&str; 13] = [
    "uyvy", "yuyv", "rgb8", "rgba8", "bgr8", "bgra8", "mono8", "nv12", "bayer_rggb8",
    "bayer_bggr8", "bayer_gbrg8", "bayer_grbg8", "16UC1",
];

fuzz_target!(|data: &[u8]| {
    if data.len() < 8 {
        return;
    }
    let (head, pixels) = data.split_at(8);
    let width = usize::from(u16::from_le_bytes([head[0], head[1]]) % 512);
    let height = usize::from(u16::from_le_bytes([head[2], head[3]]) % 512);
    let step = usize::from(u16::from_le_bytes([head[4], head[5]]));
    let encoding = NAMES[usize::from(head[6]) % NAMES.len()];
    let image = RawImage { width, height, encoding, step, data: pixels };
    if let Ok(frame) = decode_raw(&image) {
        assert_eq!((frame.width(), frame.height()), (width, height));
    }
    if let Some(e) = PixelEncoding::from_name(encoding) {
        let _ = eotn::frame::decode_raw_owned(e, width, height, step, pixels.to_vec());
    }
    let _ = decode_compressed(if head[7] % 2 == 0 { "jpeg" } else { "png" }, pixels);
});
