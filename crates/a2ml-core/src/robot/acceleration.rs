//! Joint acceleration limits, which URDF does not have: the a2ml extension attribute
//! `a2ml_acceleration` (rad/s²) on a joint's `<limit>` element, which urdf-rs and the ROS URDF
//! parsers ignore as an unknown attribute, else [`DEFAULT_ACCELERATION_PER_SECOND`] times the
//! joint's velocity limit.

use std::collections::HashMap;

use quick_xml::events::Event;

use super::RobotError;
use crate::math::Real;

/// The default acceleration limit of a joint is its velocity limit times this (1/s): the joint
/// reaches full speed from rest in 0.1 s. Human reaching peaks near 10-30 rad/s² at the
/// shoulder and elbow (3.14 rad/s here gives 31); Franka's datasheet gives the Panda 7.5-20
/// rad/s² for 2.2-2.6 rad/s (3.4-8 per second), so a robot file with datasheet values should
/// state them with the attribute.
pub const DEFAULT_ACCELERATION_PER_SECOND: Real = 10.0;

/// The attribute of `<limit>` holding a joint's acceleration limit (rad/s²).
pub const ATTRIBUTE: &str = "a2ml_acceleration";

/// Every joint's `a2ml_acceleration`, by joint name.
///
/// # Errors
/// [`RobotError::InvalidAcceleration`] for a value that is not a positive finite number;
/// [`RobotError::Urdf`] for XML that cannot be read.
pub(super) fn stated(text: &str) -> Result<HashMap<String, Real>, RobotError> {
    let mut reader = quick_xml::Reader::from_str(text);
    let mut out = HashMap::new();
    let mut joint: Option<String> = None;
    let xml_error =
        |e: &dyn std::fmt::Display| RobotError::Urdf { path: None, message: e.to_string() };
    loop {
        let event = reader.read_event().map_err(|e| xml_error(&e))?;
        let (element, opens) = match &event {
            Event::Start(e) => (e, true),
            Event::Empty(e) => (e, false),
            Event::End(e) if e.name().as_ref() == b"joint" => {
                joint = None;
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let attribute = |name: &str| -> Result<Option<String>, RobotError> {
            match element.try_get_attribute(name).map_err(|e| xml_error(&e))? {
                Some(a) => Ok(Some(a.unescape_value().map_err(|e| xml_error(&e))?.into_owned())),
                None => Ok(None),
            }
        };
        match element.name().as_ref() {
            b"joint" if opens => joint = attribute("name")?,
            b"limit" => {
                if let (Some(name), Some(text)) = (&joint, attribute(ATTRIBUTE)?) {
                    let value = text.trim().parse::<Real>().unwrap_or(Real::NAN);
                    if !(value.is_finite() && value > 0.0) {
                        return Err(RobotError::InvalidAcceleration { joint: name.clone(), text });
                    }
                    out.insert(name.clone(), value);
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_attribute_per_joint() {
        let text = r#"<robot name="r">
            <joint name="a" type="revolute"><limit lower="-1" upper="1" velocity="2" a2ml_acceleration="15"/></joint>
            <joint name="b" type="revolute"><limit lower="-1" upper="1" velocity="2"/></joint>
        </robot>"#;
        let stated = stated(text).expect("reads");
        assert_eq!(stated.get("a"), Some(&15.0));
        assert_eq!(stated.get("b"), None);
    }

    #[test]
    fn a_bad_value_names_its_joint() {
        for bad in ["-3", "fast", "0", "inf"] {
            let text = format!(
                r#"<robot name="r"><joint name="j"><limit a2ml_acceleration="{bad}"/></joint></robot>"#
            );
            assert!(matches!(
                stated(&text),
                Err(RobotError::InvalidAcceleration { joint, .. }) if joint == "j"
            ));
        }
    }
}
