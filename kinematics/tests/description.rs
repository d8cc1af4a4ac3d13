//! Reading hand descriptions: the shipped TriFingerPro, and one test per
//! error, each checking the one-line message names the key, link or joint.

mod common;

use kinematics::{DescriptionError, HandDescription};

/// A two-joint finger: base → (revolute j1) → l1 → (revolute j2) → l2 → (fixed) → tip.
fn urdf(j2_type: &str, j2_limit: &str, tip_collision: &str) -> String {
    format!(
        r#"<robot name="toy">
  <link name="root"/>
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 -0.05"/><mass value="0.1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <link name="l2"/>
  <link name="tip">{tip_collision}</link>
  <link name="side"/>
  <joint name="mount" type="fixed"><parent link="root"/><child link="base"/><origin xyz="0 0 0.3"/></joint>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="0.5" velocity="5"/></joint>
  <joint name="j2" type="{j2_type}"><parent link="l1"/><child link="l2"/><origin xyz="0 0 -0.1"/><axis xyz="1 0 0"/>{j2_limit}</joint>
  <joint name="to_tip" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0 0 -0.1"/></joint>
  <joint name="to_side" type="fixed"><parent link="root"/><child link="side"/></joint>
</robot>"#
    )
}

const LIMIT: &str = r#"<limit lower="-2" upper="0" effort="0.5" velocity="5"/>"#;
const SPHERE: &str = r#"<collision><geometry><sphere radius="0.01"/></geometry></collision>"#;

fn section(finger: &str) -> String {
    format!(
        "[object]\nradius = 0.03\nmass = 0.05\ncentre = [0.0, 0.0, 0.1]\n[friction]\nmu = 0.5\ntorsion = 0.0005\n[[finger]]\n{finger}"
    )
}

const FINGER: &str = "name = \"f\"\nbase = \"base\"\ntip = \"tip\"\n";

fn err(urdf: &str, section: &str) -> DescriptionError {
    let e = HandDescription::parse(urdf, section).expect_err("an error");
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "one line: {msg}");
    e
}

#[test]
fn toy_hand_reads() {
    let h = HandDescription::parse(&urdf("revolute", LIMIT, SPHERE), &section(FINGER)).unwrap();
    let f = &h.fingers[0];
    assert_eq!(h.frame, "root");
    assert_eq!(
        f.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>(),
        ["j1", "j2"]
    );
    assert_eq!(f.base.translation, nalgebra::Vector3::new(0.0, 0.0, 0.3));
    assert_eq!(f.tip.translation, nalgebra::Vector3::new(0.0, 0.0, -0.1));
    assert_eq!(f.tip_radius, 0.01);
    assert_eq!(f.bodies[0].mass, 0.1);
    assert!(
        f.capsules.is_empty(),
        "the tip sphere is the contact, not a capsule"
    );
    assert_eq!(h.joint_limit_margin, 0.05);
    assert_eq!(h.gravity, nalgebra::Vector3::new(0.0, 0.0, -9.81));
}

#[test]
fn trifingerpro_reads() {
    let h = common::hand();
    assert_eq!(h.robot, "trifingerpro");
    assert_eq!(h.frame, "base_link");
    assert_eq!(h.urdf_file.as_deref(), Some("trifingerpro.urdf"));
    for f in &h.fingers {
        assert_eq!(f.joints.len(), 3);
        assert_eq!(f.capsules.len(), 6);
        assert!(f.ignored_meshes.is_empty());
        assert_eq!(f.base.translation, nalgebra::Vector3::new(0.0, 0.0, 0.29));
    }
    assert_eq!((h.object.radius, h.object.mass), (0.0335, 0.058));
}

#[test]
fn unknown_link() {
    let e = err(
        &urdf("revolute", LIMIT, SPHERE),
        &section("name = \"f\"\nbase = \"base\"\ntip = \"tpi\"\n"),
    );
    assert_eq!(
        e,
        DescriptionError::UnknownLink {
            key: "finger[0].tip".into(),
            link: "tpi".into()
        }
    );
    assert_eq!(e.to_string(), "`finger[0].tip`: no link `tpi` in the URDF");
    let e = err(
        &urdf("revolute", LIMIT, SPHERE),
        &format!("frame = \"nowhere\"\n{}", section(FINGER)),
    );
    assert!(
        matches!(e, DescriptionError::UnknownLink { ref key, .. } if key == "frame"),
        "{e}"
    );
}

#[test]
fn tip_not_below_base() {
    let e = err(
        &urdf("revolute", LIMIT, SPHERE),
        &section("name = \"f\"\nbase = \"base\"\ntip = \"side\"\n"),
    );
    assert!(matches!(e, DescriptionError::TipNotBelowBase { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("`side` is not below base link `base`"),
        "{e}"
    );
}

#[test]
fn base_not_fixed_below_frame() {
    // l1 hangs from the frame through the revolute j1.
    let e = err(
        &urdf("revolute", LIMIT, SPHERE),
        &section("name = \"f\"\nbase = \"l1\"\ntip = \"tip\"\n"),
    );
    assert!(
        matches!(e, DescriptionError::BaseNotFixed { ref joint, .. } if joint == "j1"),
        "{e}"
    );
    // `side` is not below `base`.
    let e = err(
        &urdf("revolute", LIMIT, SPHERE),
        &format!("frame = \"side\"\n{}", section(FINGER)),
    );
    assert!(matches!(e, DescriptionError::BaseNotFixed { .. }), "{e}");
}

#[test]
fn non_revolute_joint() {
    let e = err(&urdf("prismatic", LIMIT, SPHERE), &section(FINGER));
    assert_eq!(
        e.to_string(),
        "finger `f`: joint `j2` is prismatic; a finger chain has revolute (and fixed) joints only"
    );
    let e = err(&urdf("continuous", "", SPHERE), &section(FINGER));
    assert!(
        matches!(e, DescriptionError::NonRevoluteJoint { ref kind, .. } if kind == "continuous"),
        "{e}"
    );
}

#[test]
fn missing_or_empty_limits() {
    let e = err(&urdf("revolute", "", SPHERE), &section(FINGER));
    assert_eq!(e.to_string(), "joint `j2`: no <limit>, or lower ≥ upper");
    let e = err(
        &urdf(
            "revolute",
            r#"<limit lower="0" upper="0" effort="1" velocity="1"/>"#,
            SPHERE,
        ),
        &section(FINGER),
    );
    assert!(
        matches!(e, DescriptionError::BadLimit { ref joint, .. } if joint == "j2"),
        "{e}"
    );
    let e = err(
        &urdf(
            "revolute",
            r#"<limit lower="-1" upper="0" effort="1" velocity="0"/>"#,
            SPHERE,
        ),
        &section(FINGER),
    );
    assert_eq!(e.to_string(), "joint `j2`: velocity limit must be positive");
    let e = err(
        &urdf(
            "revolute",
            r#"<limit lower="-1" upper="0" velocity="1"/>"#,
            SPHERE,
        ),
        &section(FINGER),
    );
    assert_eq!(e.to_string(), "joint `j2`: effort limit must be positive");
    // A margin that eats a whole range.
    let e = err(
        &urdf("revolute", LIMIT, SPHERE),
        &format!("joint_limit_margin = 1.0\n{}", section(FINGER)),
    );
    assert!(
        matches!(e, DescriptionError::BadValue { ref key, .. } if key == "joint_limit_margin"),
        "{e}"
    );
}

#[test]
fn no_tip_radius() {
    let e = err(&urdf("revolute", LIMIT, ""), &section(FINGER));
    assert!(
        e.to_string().starts_with("finger `f`: no tip radius"),
        "{e}"
    );
    // Given in the section instead: fine.
    let h = HandDescription::parse(
        &urdf("revolute", LIMIT, ""),
        &section(&format!("{FINGER}tip_radius = 0.012\n")),
    )
    .unwrap();
    assert_eq!(h.fingers[0].tip_radius, 0.012);
}

#[test]
fn section_mistakes() {
    let u = urdf("revolute", LIMIT, SPHERE);
    let e = err(&u, &section(&format!("{FINGER}tip_radus = 0.01\n")));
    assert!(
        matches!(e, DescriptionError::Section(ref m) if m.contains("tip_radus")),
        "{e}"
    );
    let e = err(
        &u,
        &section(FINGER).replace("radius = 0.03", "radius = -0.03"),
    );
    assert_eq!(
        e.to_string(),
        "`object.radius` = -0.03: must be positive and finite"
    );
    let e = err(&u, &section(FINGER).replace("mu = 0.5", "mu = 0.0"));
    assert!(
        matches!(e, DescriptionError::BadValue { ref key, .. } if key == "friction.mu"),
        "{e}"
    );
    let e = err(&u, &section(&format!("{FINGER}tip_patch_deg = 0.0\n")));
    assert!(
        matches!(e, DescriptionError::BadValue { ref key, .. } if key == "finger[0].tip_patch_deg"),
        "{e}"
    );
    let e = err(&u, &format!("{}[[finger]]\n{FINGER}", section(FINGER)));
    assert_eq!(e, DescriptionError::Fingers("two [[finger]] share a name"));
    let e = err(&u, &section("").replace("[[finger]]\n", ""));
    assert_eq!(e, DescriptionError::Fingers("no [[finger]]"));
}

#[test]
fn bad_urdf_and_axis() {
    let e = err(
        "<robot name=\"x\"><link name=\"a\"></robot>",
        &section(FINGER),
    );
    assert!(matches!(e, DescriptionError::Urdf(_)), "{e}");
    let u = urdf("revolute", LIMIT, SPHERE).replacen(
        r#"<axis xyz="1 0 0"/>"#,
        r#"<axis xyz="0 0 0"/>"#,
        1,
    );
    assert_eq!(
        err(&u, &section(FINGER)).to_string(),
        "joint `j1`: axis must be a finite non-zero vector"
    );
}

#[test]
fn chain_joint_count_and_primitives() {
    let h = HandDescription::parse(&urdf("revolute", LIMIT, SPHERE), &section(FINGER)).unwrap();
    let e = kinematics::Chain::<3>::from_description(&h.fingers[0], 0.05).unwrap_err();
    assert_eq!(
        e.to_string(),
        "finger `f` has 2 revolute joints, this chain type has 3"
    );
    // A box on l1 becomes one capsule; a mesh is listed as ignored.
    let u = urdf("revolute", LIMIT, SPHERE).replace(
        r#"<link name="l2"/>"#,
        r#"<link name="l2"><collision><geometry><box size="0.02 0.04 0.1"/></geometry></collision><collision><geometry><mesh filename="x.stl"/></geometry></collision></link>"#,
    );
    let h = HandDescription::parse(&u, &section(FINGER)).unwrap();
    let f = &h.fingers[0];
    assert_eq!(f.ignored_meshes, ["l2"]);
    assert_eq!(f.capsules.len(), 1);
    let c = f.capsules[0];
    assert_eq!(c.segment, 2);
    assert!((c.capsule.radius - 0.5 * (0.02f64.powi(2) + 0.04f64.powi(2)).sqrt()).abs() < 1e-15);
    assert!(((c.capsule.b - c.capsule.a).norm() - 0.1).abs() < 1e-15);
}
