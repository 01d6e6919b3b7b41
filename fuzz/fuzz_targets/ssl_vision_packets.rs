//! SSL-Vision packets as `udp://` listeners and logs take them: the wrapper's decoder, the
//! detection frame into eotn's units, and a geometry message into a field description.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(packet) = eotn::ssl_vision::decode_packet(data) {
        if let Some(d) = &packet.detection {
            let frame = eotn::ssl_vision::CameraFrame::from_message(d);
            let _ = frame.t_capture_ns();
        }
        if let Some(g) = &packet.geometry {
            let _ = eotn::ssl_vision::geometry::field_description(&g.field);
        }
    }
});
