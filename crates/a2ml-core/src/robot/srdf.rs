//! The allowed collision pairs of an SRDF (MoveIt's semantic robot description): every
//! `<disable_collisions link1="…" link2="…"/>`; the rest of the document (groups, end
//! effectors, virtual joints, states) is not a2ml's and is skipped. roxmltree reads it here,
//! as it reads the URDF in `urdf.rs`.

use super::RobotError;

/// A `<disable_collisions>` element: two link names and the element's line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct DisabledPair {
    pub link1: String,
    pub link2: String,
    pub line: u32,
}

/// The disabled pairs of an SRDF document, in file order.
///
/// # Errors
/// [`RobotError::Srdf`] for malformed XML, a root other than `<robot>`, or a
/// `<disable_collisions>` without both link attributes; the message names the line.
pub(crate) fn disabled_pairs(text: &str) -> Result<Vec<DisabledPair>, RobotError> {
    let error = |line: Option<u32>, message: String| RobotError::Srdf { path: None, line, message };
    let doc =
        roxmltree::Document::parse(text).map_err(|e| error(Some(e.pos().row), e.to_string()))?;
    let line_of = |node: roxmltree::Node| doc.text_pos_at(node.range().start).row;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(error(Some(line_of(root)), "the root element must be <robot>".into()));
    }
    let mut pairs = Vec::new();
    for node in root.children().filter(|n| n.has_tag_name("disable_collisions")) {
        let line = line_of(node);
        let attribute = |name: &str| {
            node.attribute(name).filter(|v| !v.trim().is_empty()).map(str::to_owned).ok_or_else(
                || error(Some(line), format!("<disable_collisions> needs a `{name}` attribute")),
            )
        };
        pairs.push(DisabledPair { link1: attribute("link1")?, link2: attribute("link2")?, line });
    }
    Ok(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_read_and_bad_documents_located() {
        let text = "<robot name=\"r\">\n  <group name=\"arm\"/>\n  <disable_collisions \
                    link1=\"a\" link2=\"b\" reason=\"Never\"/>\n</robot>";
        let pairs = disabled_pairs(text).expect("valid");
        assert_eq!(pairs, vec![DisabledPair { link1: "a".into(), link2: "b".into(), line: 3 }]);
        let missing = "<robot>\n\n<disable_collisions link1=\"a\"/></robot>";
        match disabled_pairs(missing) {
            Err(RobotError::Srdf { line: Some(3), message, .. }) => {
                assert!(message.contains("link2"), "{message}")
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            disabled_pairs("<robot><disable_collisions"),
            Err(RobotError::Srdf { line: Some(1), .. })
        ));
        assert!(matches!(disabled_pairs("<srdf/>"), Err(RobotError::Srdf { .. })));
    }
}
