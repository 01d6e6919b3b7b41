//! Streams with several cameras: a camera other than the first written on its own topic with
//! its own channels (docs/formats.md, "Several cameras").

use std::collections::BTreeMap;

use foxglove::Encode as _;

use super::super::schema::{
    EXTRA_SCHEMA_NAME, GROUND_TRUTH_SCHEMA_NAME, RECOGNITION_SCHEMA_NAME, SENSORS_SCHEMA_NAME,
    any_json_schema, encode_image, object_json_schema, sensors_json_schema,
};
use super::super::{
    ANNOTATIONS_TOPIC, FrameRecord, GROUND_TRUTH_TOPIC, RECOGNITION_TOPIC, SENSORS_TOPIC,
    StreamError,
};
use super::StreamWriter;
use crate::formats::{ImageMessage, MessageKind};

impl StreamWriter {
    /// Appends one frame of the camera `camera` (an image topic) with its data, in the layout
    /// of several cameras (docs/formats.md): the first camera's (`/camera/image`,
    /// `/camera/image/compressed`) exactly as [`StreamWriter::write_with_image`] writes it; any
    /// other camera's image on its own topic, its sensors, ground truth, recognition and
    /// annotations on `CAMERA/sensors`, `CAMERA/ground_truth`, `CAMERA/recognition`,
    /// `CAMERA/annotations`; extra channels as they are named.
    ///
    /// # Errors
    /// As [`StreamWriter::write`]; a camera topic that does not start with `/` or is one of the
    /// stream's fixed channels.
    pub fn write_camera(
        &mut self,
        camera: &str,
        record: &FrameRecord,
        image: Option<&ImageMessage>,
    ) -> Result<(), StreamError> {
        if crate::camera::is_default_camera(camera) {
            return self.write_with_image(record, image);
        }
        let path = self.path.clone();
        let bad = |detail: String| StreamError::BadRecord {
            path: path.clone(),
            time_ns: record.time_ns,
            detail,
        };
        if !camera.starts_with('/')
            || [
                SENSORS_TOPIC,
                GROUND_TRUTH_TOPIC,
                RECOGNITION_TOPIC,
                ANNOTATIONS_TOPIC,
            ]
            .contains(&camera)
            || crate::camera::CameraChannel::of(camera).is_some()
        {
            return Err(bad(format!("'{camera}' cannot be a camera's topic")));
        }
        let mut bytes = std::mem::take(&mut self.buf);
        bytes.clear();
        let kind = match image {
            Some(message) => message.encode_foxglove(&mut bytes).map_err(&bad)?,
            None => {
                encode_image(
                    record.time_ns,
                    &record.frame,
                    self.image_encoding,
                    &mut bytes,
                )
                .map_err(|e| bad(e.to_string()))?;
                MessageKind::FoxgloveRawImage
            }
        };
        let channel = self.camera_image_channel(camera, kind);
        let written = channel.and_then(|c| self.put(c, record.time_ns, &bytes));
        self.buf = bytes;
        written?;
        let own = |c: crate::camera::CameraChannel| c.topic(camera);
        let sensors = record.sensors.as_ref().map(|s| {
            let (clean, _) = s.sanitised();
            serde_json::to_value(clean).unwrap_or_default()
        });
        let jsons = [
            (
                own(crate::camera::CameraChannel::Sensors),
                sensors.as_ref(),
                SENSORS_SCHEMA_NAME,
            ),
            (
                own(crate::camera::CameraChannel::GroundTruth),
                record.ground_truth.as_ref(),
                GROUND_TRUTH_SCHEMA_NAME,
            ),
            (
                own(crate::camera::CameraChannel::Recognition),
                record.recognition.as_ref(),
                RECOGNITION_SCHEMA_NAME,
            ),
        ];
        let extra = record
            .extra
            .iter()
            .map(|(t, v)| (t.clone(), Some(v), EXTRA_SCHEMA_NAME));
        for (topic, value, schema) in jsons.into_iter().chain(extra) {
            if let Some(v) = value {
                let id = self.json_channel_with(&topic, schema)?;
                let json = serde_json::to_vec(v).map_err(|e| bad(e.to_string()))?;
                self.put(id, record.time_ns, &json)?;
            }
        }
        if let Some(a) = &record.annotations {
            let id =
                self.camera_annotations_channel(&own(crate::camera::CameraChannel::Annotations))?;
            let mut bytes = Vec::with_capacity(a.encoded_len().unwrap_or(0));
            a.encode(&mut bytes).map_err(|e| bad(e.to_string()))?;
            self.put(id, record.time_ns, &bytes)?;
        }
        self.frame_written()
    }

    /// The image channel of a camera other than the first, of its message type
    /// (`foxglove.RawImage` or `foxglove.CompressedImage`), added with its first frame.
    fn camera_image_channel(
        &mut self,
        camera: &str,
        kind: MessageKind,
    ) -> Result<u16, StreamError> {
        let compressed = kind == MessageKind::FoxgloveCompressedImage;
        let key = (camera.to_owned(), compressed);
        if let Some(&id) = self.camera_images.get(&key) {
            return Ok(id);
        }
        let schema = if compressed {
            foxglove::messages::CompressedImage::get_schema()
        } else {
            foxglove::messages::RawImage::get_schema()
        }
        .ok_or_else(|| StreamError::Corrupt {
            path: self.partial.clone(),
            detail: "the foxglove image schemas are not available".to_owned(),
        })?;
        let schema_id = self
            .mcap
            .add_schema(&schema.name, &schema.encoding, &schema.data)
            .map_err(self.mcap_err("cannot add an image schema"))?;
        let id = self
            .mcap
            .add_channel(schema_id, camera, "protobuf", &BTreeMap::new())
            .map_err(self.mcap_err("cannot add a camera's image channel"))?;
        self.camera_images.insert(key, id);
        Ok(id)
    }

    /// The `foxglove.ImageAnnotations` channel of a camera other than the first.
    fn camera_annotations_channel(&mut self, topic: &str) -> Result<u16, StreamError> {
        if let Some(&id) = self.lazy_channels.get(topic) {
            return Ok(id);
        }
        let id = self.add_annotations_channel(topic)?;
        self.lazy_channels.insert(topic.to_owned(), id);
        Ok(id)
    }

    /// A JSON channel of a camera other than the first, with the schema `schema_name` names.
    fn json_channel_with(&mut self, topic: &str, schema_name: &str) -> Result<u16, StreamError> {
        if let Some(&id) = self.lazy_channels.get(topic) {
            return Ok(id);
        }
        let schema = match schema_name {
            SENSORS_SCHEMA_NAME => sensors_json_schema(),
            EXTRA_SCHEMA_NAME => any_json_schema(),
            _ => object_json_schema(schema_name, "One camera's per-frame data."),
        };
        let schema_id = self
            .mcap
            .add_schema(schema_name, "jsonschema", schema.to_string().as_bytes())
            .map_err(self.mcap_err("cannot add a schema"))?;
        let id = self
            .mcap
            .add_channel(schema_id, topic, "json", &BTreeMap::new())
            .map_err(self.mcap_err("cannot add a channel"))?;
        self.lazy_channels.insert(topic.to_owned(), id);
        Ok(id)
    }
}
