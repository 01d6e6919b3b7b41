//! The SSL-Vision messages (proto2), declared by hand from the protocol's public description:
//! each field's number, type and label, written as `#[derive(prost::Message)]` structs. No
//! `.proto` file is copied (ssl-vision's are GPL) and nothing is generated at build time, so
//! `cargo build` needs only Rust.
//!
//! Units as the league sends them: positions in millimetres in the field frame (origin at the
//! centre, x along the field's length, y to its left), angles in radians counter-clockwise,
//! pixels in the camera's image, times in seconds. `required` fields are always written, as
//! proto2 readers (ssl-vision's clients) insist; a reader here takes a missing one as zero.

/// The packet ssl-vision multicasts: a detection frame, a geometry message, or both.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslWrapperPacket {
    /// One camera's detections of one frame.
    #[prost(message, optional, tag = "1")]
    pub detection: Option<SslDetectionFrame>,
    /// The field and the cameras' calibrations.
    #[prost(message, optional, tag = "2")]
    pub geometry: Option<SslGeometryData>,
}

/// One camera's detections in one frame.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslDetectionFrame {
    /// The camera's frame counter.
    #[prost(uint32, required, tag = "1")]
    pub frame_number: u32,
    /// When the frame was captured, seconds.
    #[prost(double, required, tag = "2")]
    pub t_capture: f64,
    /// When the packet was sent, seconds.
    #[prost(double, required, tag = "3")]
    pub t_sent: f64,
    /// Which camera.
    #[prost(uint32, required, tag = "4")]
    pub camera_id: u32,
    /// Balls seen.
    #[prost(message, repeated, tag = "5")]
    pub balls: Vec<SslDetectionBall>,
    /// Robots of the yellow team.
    #[prost(message, repeated, tag = "6")]
    pub robots_yellow: Vec<SslDetectionRobot>,
    /// Robots of the blue team.
    #[prost(message, repeated, tag = "7")]
    pub robots_blue: Vec<SslDetectionRobot>,
    /// The camera's own capture timestamp, seconds (not necessarily Unix time).
    #[prost(double, optional, tag = "8")]
    pub t_capture_camera: Option<f64>,
}

/// A ball seen by one camera.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslDetectionBall {
    /// Confidence, 0–1.
    #[prost(float, required, tag = "1")]
    pub confidence: f32,
    /// Blob area, pixels.
    #[prost(uint32, optional, tag = "2")]
    pub area: Option<u32>,
    /// Field x, millimetres.
    #[prost(float, required, tag = "3")]
    pub x: f32,
    /// Field y, millimetres.
    #[prost(float, required, tag = "4")]
    pub y: f32,
    /// Height, millimetres.
    #[prost(float, optional, tag = "5")]
    pub z: Option<f32>,
    /// Image x, pixels.
    #[prost(float, required, tag = "6")]
    pub pixel_x: f32,
    /// Image y, pixels.
    #[prost(float, required, tag = "7")]
    pub pixel_y: f32,
}

/// A robot seen by one camera.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslDetectionRobot {
    /// Confidence, 0–1.
    #[prost(float, required, tag = "1")]
    pub confidence: f32,
    /// Its pattern's id.
    #[prost(uint32, optional, tag = "2")]
    pub robot_id: Option<u32>,
    /// Field x, millimetres.
    #[prost(float, required, tag = "3")]
    pub x: f32,
    /// Field y, millimetres.
    #[prost(float, required, tag = "4")]
    pub y: f32,
    /// Heading, radians counter-clockwise from +x.
    #[prost(float, optional, tag = "5")]
    pub orientation: Option<f32>,
    /// Image x, pixels.
    #[prost(float, required, tag = "6")]
    pub pixel_x: f32,
    /// Image y, pixels.
    #[prost(float, required, tag = "7")]
    pub pixel_y: f32,
    /// The marker's height above the ground, millimetres.
    #[prost(float, optional, tag = "8")]
    pub height: Option<f32>,
}

/// The field and the cameras' calibrations.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslGeometryData {
    /// The field's size and markings.
    #[prost(message, required, tag = "1")]
    pub field: SslGeometryFieldSize,
    /// One calibration per camera.
    #[prost(message, repeated, tag = "2")]
    pub calib: Vec<SslGeometryCameraCalibration>,
}

/// A 2-D vector, millimetres.
#[derive(Clone, Copy, PartialEq, ::prost::Message)]
pub struct Vector2f {
    /// x, millimetres.
    #[prost(float, required, tag = "1")]
    pub x: f32,
    /// y, millimetres.
    #[prost(float, required, tag = "2")]
    pub y: f32,
}

/// A painted straight line, along its centre.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslFieldLineSegment {
    /// Its name (`TopTouchLine`, …).
    #[prost(string, required, tag = "1")]
    pub name: String,
    /// One end, millimetres.
    #[prost(message, required, tag = "2")]
    pub p1: Vector2f,
    /// The other end, millimetres.
    #[prost(message, required, tag = "3")]
    pub p2: Vector2f,
    /// Line width, millimetres.
    #[prost(float, required, tag = "4")]
    pub thickness: f32,
    /// What it is ([`FieldShapeType`]).
    #[prost(enumeration = "FieldShapeType", optional, tag = "5")]
    pub r#type: Option<i32>,
}

/// A painted arc, counter-clockwise from `a1` to `a2`.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslFieldCircularArc {
    /// Its name (`CenterCircle`, …).
    #[prost(string, required, tag = "1")]
    pub name: String,
    /// Centre, millimetres.
    #[prost(message, required, tag = "2")]
    pub center: Vector2f,
    /// Radius to the line's centre, millimetres.
    #[prost(float, required, tag = "3")]
    pub radius: f32,
    /// Start angle, radians.
    #[prost(float, required, tag = "4")]
    pub a1: f32,
    /// End angle, radians.
    #[prost(float, required, tag = "5")]
    pub a2: f32,
    /// Line width, millimetres.
    #[prost(float, required, tag = "6")]
    pub thickness: f32,
    /// What it is ([`FieldShapeType`]).
    #[prost(enumeration = "FieldShapeType", optional, tag = "7")]
    pub r#type: Option<i32>,
}

/// The field's size and markings, millimetres.
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslGeometryFieldSize {
    /// Between the goal lines.
    #[prost(int32, required, tag = "1")]
    pub field_length: i32,
    /// Between the touch lines.
    #[prost(int32, required, tag = "2")]
    pub field_width: i32,
    /// Between the goal posts.
    #[prost(int32, required, tag = "3")]
    pub goal_width: i32,
    /// Behind the goal line.
    #[prost(int32, required, tag = "4")]
    pub goal_depth: i32,
    /// Carpet beyond the lines.
    #[prost(int32, required, tag = "5")]
    pub boundary_width: i32,
    /// The straight lines.
    #[prost(message, repeated, tag = "6")]
    pub field_lines: Vec<SslFieldLineSegment>,
    /// The arcs.
    #[prost(message, repeated, tag = "7")]
    pub field_arcs: Vec<SslFieldCircularArc>,
    /// Penalty area depth.
    #[prost(int32, optional, tag = "8")]
    pub penalty_area_depth: Option<i32>,
    /// Penalty area width.
    #[prost(int32, optional, tag = "9")]
    pub penalty_area_width: Option<i32>,
    /// Centre circle radius.
    #[prost(int32, optional, tag = "10")]
    pub center_circle_radius: Option<i32>,
    /// Line width.
    #[prost(int32, optional, tag = "11")]
    pub line_thickness: Option<i32>,
    /// Goal centre to penalty mark.
    #[prost(int32, optional, tag = "12")]
    pub goal_center_to_penalty_mark: Option<i32>,
    /// Goal height.
    #[prost(int32, optional, tag = "13")]
    pub goal_height: Option<i32>,
    /// Ball radius.
    #[prost(float, optional, tag = "14")]
    pub ball_radius: Option<f32>,
    /// Largest robot radius allowed.
    #[prost(float, optional, tag = "15")]
    pub max_robot_radius: Option<f32>,
}

/// One camera's calibration in ssl-vision's model: a pinhole with one radial distortion
/// coefficient (`distortion`, κ: undistorted radius `r_u = r_d·(1 + κ·r_d²)` in normalised
/// coordinates, κ ≤ 0 meaning none) and the pose `p_camera = q·p_field + t` (millimetres; the
/// camera's z along the optical axis, x right, y down in the image; `q` with `q3` the scalar
/// part).
#[derive(Clone, PartialEq, ::prost::Message)]
pub struct SslGeometryCameraCalibration {
    /// Which camera.
    #[prost(uint32, required, tag = "1")]
    pub camera_id: u32,
    /// Focal length, pixels.
    #[prost(float, required, tag = "2")]
    pub focal_length: f32,
    /// Principal point x, pixels.
    #[prost(float, required, tag = "3")]
    pub principal_point_x: f32,
    /// Principal point y, pixels.
    #[prost(float, required, tag = "4")]
    pub principal_point_y: f32,
    /// Radial distortion κ.
    #[prost(float, required, tag = "5")]
    pub distortion: f32,
    /// Rotation quaternion, x part.
    #[prost(float, required, tag = "6")]
    pub q0: f32,
    /// Rotation quaternion, y part.
    #[prost(float, required, tag = "7")]
    pub q1: f32,
    /// Rotation quaternion, z part.
    #[prost(float, required, tag = "8")]
    pub q2: f32,
    /// Rotation quaternion, scalar part.
    #[prost(float, required, tag = "9")]
    pub q3: f32,
    /// Translation x, millimetres (camera frame).
    #[prost(float, required, tag = "10")]
    pub tx: f32,
    /// Translation y, millimetres.
    #[prost(float, required, tag = "11")]
    pub ty: f32,
    /// Translation z, millimetres.
    #[prost(float, required, tag = "12")]
    pub tz: f32,
    /// The camera's position in the field, x, millimetres.
    #[prost(float, optional, tag = "13")]
    pub derived_camera_world_tx: Option<f32>,
    /// The camera's position in the field, y, millimetres.
    #[prost(float, optional, tag = "14")]
    pub derived_camera_world_ty: Option<f32>,
    /// The camera's position in the field, z, millimetres.
    #[prost(float, optional, tag = "15")]
    pub derived_camera_world_tz: Option<f32>,
    /// Image width, pixels.
    #[prost(uint32, optional, tag = "16")]
    pub pixel_image_width: Option<u32>,
    /// Image height, pixels.
    #[prost(uint32, optional, tag = "17")]
    pub pixel_image_height: Option<u32>,
}

/// What a field line or arc is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, ::prost::Enumeration)]
#[repr(i32)]
pub enum FieldShapeType {
    /// Not said.
    Undefined = 0,
    /// The centre circle.
    CenterCircle = 1,
    /// The touch line at +y.
    TopTouchLine = 2,
    /// The touch line at −y.
    BottomTouchLine = 3,
    /// The goal line at −x.
    LeftGoalLine = 4,
    /// The goal line at +x.
    RightGoalLine = 5,
    /// The line at x = 0 across the field.
    HalfwayLine = 6,
    /// The line along y = 0.
    CenterLine = 7,
    /// The front of the −x penalty area.
    LeftPenaltyStretch = 8,
    /// The front of the +x penalty area.
    RightPenaltyStretch = 9,
    /// A side of the −x penalty area.
    LeftFieldLeftPenaltyStretch = 10,
    /// The other side of the −x penalty area.
    LeftFieldRightPenaltyStretch = 11,
    /// A side of the +x penalty area.
    RightFieldLeftPenaltyStretch = 12,
    /// The other side of the +x penalty area.
    RightFieldRightPenaltyStretch = 13,
}

impl FieldShapeType {
    /// The name the league gives the shape (the enum value's name), as a line's `name`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Undefined => "Undefined",
            Self::CenterCircle => "CenterCircle",
            Self::TopTouchLine => "TopTouchLine",
            Self::BottomTouchLine => "BottomTouchLine",
            Self::LeftGoalLine => "LeftGoalLine",
            Self::RightGoalLine => "RightGoalLine",
            Self::HalfwayLine => "HalfwayLine",
            Self::CenterLine => "CenterLine",
            Self::LeftPenaltyStretch => "LeftPenaltyStretch",
            Self::RightPenaltyStretch => "RightPenaltyStretch",
            Self::LeftFieldLeftPenaltyStretch => "LeftFieldLeftPenaltyStretch",
            Self::LeftFieldRightPenaltyStretch => "LeftFieldRightPenaltyStretch",
            Self::RightFieldLeftPenaltyStretch => "RightFieldLeftPenaltyStretch",
            Self::RightFieldRightPenaltyStretch => "RightFieldRightPenaltyStretch",
        }
    }
}
