//! The JSON schemas of the MCAP channels (schema encoding `jsonschema`).
//!
//! The trace's own channels carry the trace's lines verbatim, so their
//! schemas describe `gait-trajectory/1` (docs/design/10-traces.md). The
//! 3D channels use Foxglove's well-known schema names, which is what makes
//! Foxglove's 3D panel draw them; their schemas here describe only the
//! fields this crate writes (a subset of Foxglove's own).

/// Schema of `/gaitd/header`: the trace's header line. Writers add keys
/// (the daemon the goal and its outcome, `gaitctl plan` its goals), so
/// other properties are allowed.
pub const HEADER: &str = r#"{
  "title": "gaitd.TraceHeader",
  "description": "Header of a gait-trajectory/1 trace: the model a replay must use. SI units (m, s, N), hand frame.",
  "type": "object",
  "properties": {
    "format": {"type": "string", "const": "gait-trajectory/1"},
    "object_radius": {"type": "number", "description": "sphere radius R [m]"},
    "fingertip_radius": {"type": "number", "description": "fingertip radius r [m]"},
    "mu": {"type": "number", "description": "friction coefficient"},
    "dt": {"type": "number", "description": "control period [s]; sample times are tick * dt"},
    "workspace_half_angle_deg": {"type": "number"},
    "roll_limit_deg": {"type": "number"},
    "friction_angle_deg": {"type": "number"},
    "finger_azimuth_deg": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
    "object_mass": {"type": "number", "description": "[kg]"},
    "mu_torsion": {"type": "number", "description": "torsion coefficient [m]"},
    "gravity": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "[m/s^2], hand frame"},
    "max_grip": {"type": "number", "description": "force limit [N]"},
    "disturbance_force": {"type": "number", "description": "[N]"},
    "hand": {"type": "string", "description": "\"chains\" on a hand of finger chains (absent: free fingertips)"},
    "hand_description": {"type": "string", "description": "a chain hand's description (its hand section file, absolute path), which names its URDF"}
  },
  "required": ["format", "object_radius", "fingertip_radius", "mu", "dt"]
}"#;

/// Schema of `/gaitd/sample`: one control tick's line.
pub const SAMPLE: &str = r#"{
  "title": "gaitd.TraceSample",
  "description": "One control tick of a gait-trajectory/1 trace. SI units, hand frame; quaternions [w, x, y, z], Hamilton, unit.",
  "type": "object",
  "properties": {
    "t": {"type": "number", "minimum": 0, "description": "time [s], tick * dt; the message's log time in ns"},
    "object_q": {"type": "array", "items": {"type": "number"}, "minItems": 4, "maxItems": 4, "description": "commanded object orientation, world-from-body [w, x, y, z]"},
    "phase": {"type": "string", "description": "hold, planning, roll, rotate, transfer, place, lift, moving, stopping or safe_hold"},
    "fingers": {
      "type": "array",
      "minItems": 3,
      "maxItems": 3,
      "items": {
        "type": "object",
        "properties": {
          "p": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "fingertip centre [m]"},
          "q": {"type": "array", "items": {"type": "number"}, "minItems": 4, "maxItems": 4, "description": "fingertip orientation, world-from-fingertip [w, x, y, z]"},
          "contact": {"type": "boolean", "description": "touching the object, |p| = R + r"},
          "grip_force": {"type": ["number", "null"], "description": "intended normal force [N], 0 when not in contact"},
          "roll": {"type": ["number", "null"], "description": "roll angle [rad]"},
          "joints": {"type": "array", "items": {"type": ["number", "null"]}, "minItems": 3, "maxItems": 3, "description": "a chain hand's commanded joints, base to tip [rad]"}
        },
        "required": ["p", "q", "contact"]
      }
    },
    "fc": {"type": "boolean", "description": "force closure of the commanded grasp"},
    "fc_margin": {"type": ["number", "null"], "description": "force-closure slack [rad]"},
    "load_margin": {"type": ["number", "null"], "description": "max_grip minus the largest normal force the load needs [N]; null when no grip holds it"},
    "remaining_angle": {"type": ["number", "null"], "description": "angle still to rotate [rad]"},
    "gaits": {"type": "integer", "minimum": 0, "description": "gaits done"},
    "estimate_epoch": {"type": "integer", "minimum": 0, "description": "changes where the object estimate was re-based on a measurement"},
    "joint_margin": {"type": ["number", "null"], "description": "a chain hand's tightest joint margin inside its limits [rad]"}
  },
  "required": ["t", "object_q", "fingers"]
}"#;

/// Schema of `/gaitd/tf` (`foxglove.FrameTransforms`): the frames
/// `object` and `fingertip1`..`fingertip3` in the frame `hand`.
pub const FRAME_TRANSFORMS: &str = r##"{
  "title": "foxglove.FrameTransforms",
  "description": "The object's and the fingertips' frames in the hand frame (subset of Foxglove's schema: the fields written here)",
  "type": "object",
  "properties": {
    "transforms": {
      "type": "array",
      "items": {
        "type": "object",
        "properties": {
          "timestamp": {"$ref": "#/$defs/time"},
          "parent_frame_id": {"type": "string"},
          "child_frame_id": {"type": "string"},
          "translation": {"$ref": "#/$defs/vector3"},
          "rotation": {"$ref": "#/$defs/quaternion"}
        },
        "required": ["timestamp", "parent_frame_id", "child_frame_id", "translation", "rotation"]
      }
    }
  },
  "required": ["transforms"],
  "$defs": {
    "time": {
      "type": "object",
      "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}
      },
      "required": ["sec", "nsec"]
    },
    "vector3": {
      "type": "object",
      "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}},
      "required": ["x", "y", "z"]
    },
    "quaternion": {
      "type": "object",
      "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}},
      "required": ["x", "y", "z", "w"]
    }
  }
}"##;

/// Schema of `/gaitd/scene` (`foxglove.SceneUpdate`): the sphere with its
/// axes, and the fingertips (opaque while touching), each fixed to its
/// frame of `/gaitd/tf`.
pub const SCENE_UPDATE: &str = r##"{
  "title": "foxglove.SceneUpdate",
  "description": "The sphere and the fingertips (subset of Foxglove's schema: the fields written here; the other primitive lists are empty)",
  "type": "object",
  "properties": {
    "deletions": {"type": "array", "maxItems": 0},
    "entities": {
      "type": "array",
      "items": {
        "type": "object",
        "properties": {
          "timestamp": {"$ref": "#/$defs/time"},
          "frame_id": {"type": "string"},
          "id": {"type": "string"},
          "lifetime": {"$ref": "#/$defs/time"},
          "frame_locked": {"type": "boolean"},
          "metadata": {"type": "array", "maxItems": 0},
          "arrows": {
            "type": "array",
            "items": {
              "type": "object",
              "properties": {
                "pose": {"$ref": "#/$defs/pose"},
                "shaft_length": {"type": "number"},
                "shaft_diameter": {"type": "number"},
                "head_length": {"type": "number"},
                "head_diameter": {"type": "number"},
                "color": {"$ref": "#/$defs/color"}
              },
              "required": ["pose", "shaft_length", "shaft_diameter", "head_length", "head_diameter", "color"]
            }
          },
          "spheres": {
            "type": "array",
            "items": {
              "type": "object",
              "properties": {
                "pose": {"$ref": "#/$defs/pose"},
                "size": {"$ref": "#/$defs/vector3"},
                "color": {"$ref": "#/$defs/color"}
              },
              "required": ["pose", "size", "color"]
            }
          },
          "cubes": {"type": "array", "maxItems": 0},
          "cylinders": {"type": "array", "maxItems": 0},
          "lines": {"type": "array", "maxItems": 0},
          "triangles": {"type": "array", "maxItems": 0},
          "texts": {"type": "array", "maxItems": 0},
          "models": {"type": "array", "maxItems": 0}
        },
        "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"]
      }
    }
  },
  "required": ["deletions", "entities"],
  "$defs": {
    "time": {
      "type": "object",
      "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}
      },
      "required": ["sec", "nsec"]
    },
    "vector3": {
      "type": "object",
      "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}},
      "required": ["x", "y", "z"]
    },
    "quaternion": {
      "type": "object",
      "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}},
      "required": ["x", "y", "z", "w"]
    },
    "pose": {
      "type": "object",
      "properties": {"position": {"$ref": "#/$defs/vector3"}, "orientation": {"$ref": "#/$defs/quaternion"}},
      "required": ["position", "orientation"]
    },
    "color": {
      "type": "object",
      "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}},
      "required": ["r", "g", "b", "a"]
    }
  }
}"##;
