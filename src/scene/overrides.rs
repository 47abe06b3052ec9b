//! Scene overrides: `PATH=VALUE` edits of a scene's text (`magsep run SCENE --set
//! brownian.duration=2.0 --set particles[0].shape.radius=75e-9`, and every point of a sweep).
//!
//! `PATH` is a dotted key path with `[i]` for an entry of an array (of tables):
//! `brownian.duration`, `particles[0].shape.radius`, `fibres[2].center[0]`. `VALUE` is a TOML
//! value (`2.0`, `"fire"`, `[1, 2, 3]`, `{ kind = "sphere", radius = 1e-7 }`); a bare word that
//! is not valid TOML (`fire`) is taken as a string. Values keep the scene's units (SI).
//!
//! The overrides are applied with `toml_edit` to the scene document, so comments and layout
//! are kept, and the edited text is what is then parsed and validated exactly like a file: a
//! wrong value or an unknown key is reported at its key path by [`parse_scene`](super::parse_scene).
//! Setting a key that does not exist in a table is allowed (missing tables on the way are
//! created); the validator then judges it. An index past the end of an array, or a key below a
//! value that is not a table, is an error at that path.
//!
//! ```
//! use magsep::scene::overrides::{Override, apply_overrides};
//! let text = "[simulation]\npipeline = \"packing\"\nseed = 1 # the seed\n";
//! let ov = Override::parse("simulation.seed=7").unwrap();
//! let edited = apply_overrides(text, &[ov]).unwrap();
//! assert_eq!(edited, "[simulation]\npipeline = \"packing\"\nseed = 7 # the seed\n");
//! let bad = Override::parse("simulation.seed[2]=7").unwrap();
//! let errors = apply_overrides(text, &[bad]).unwrap_err();
//! assert_eq!(errors.0[0].path, "simulation.seed[2]");
//! ```

use std::fmt;

use toml_edit::{ArrayOfTables, DocumentMut, InlineTable, Item, Table, Value};

use super::{SceneError, SceneErrors};

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    /// A key of a table.
    Key(String),
    /// An entry of an array or array of tables (0-based).
    Index(usize),
}

/// A parsed key path such as `particles[0].shape.radius`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPath(pub Vec<Segment>);

impl KeyPath {
    /// Parse `path`: keys of letters, digits, `_` and `-`, joined by `.`, each followed by
    /// any number of `[i]`.
    ///
    /// # Errors
    /// What is wrong with the path.
    pub fn parse(path: &str) -> Result<Self, String> {
        let mut segments = Vec::new();
        if path.is_empty() {
            return Err("empty key path".into());
        }
        for part in path.split('.') {
            let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
            let key_ok = key
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if key.is_empty() || !key_ok {
                return Err(format!(
                    "bad key path `{path}`: `{part}` is not a key (letters, digits, _ and -, \
                     then any [index])"
                ));
            }
            segments.push(Segment::Key(key.to_string()));
            while !rest.is_empty() {
                let close = rest.find(']').filter(|_| rest.starts_with('['));
                let index = close.and_then(|c| rest[1..c].parse::<usize>().ok());
                let (Some(c), Some(i)) = (close, index) else {
                    return Err(format!(
                        "bad key path `{path}`: `{rest}` is not an index such as [0]"
                    ));
                };
                segments.push(Segment::Index(i));
                rest = &rest[c + 1..];
            }
        }
        Ok(Self(segments))
    }

    /// The path of the first `n` segments, as written (`particles[0].shape`).
    pub fn prefix(&self, n: usize) -> String {
        let mut out = String::new();
        for s in &self.0[..n.min(self.0.len())] {
            match s {
                Segment::Key(k) if out.is_empty() => out.push_str(k),
                Segment::Key(k) => {
                    out.push('.');
                    out.push_str(k);
                }
                Segment::Index(i) => out.push_str(&format!("[{i}]")),
            }
        }
        out
    }

    /// The value at this path in a JSON document (a run's summary), if any.
    pub fn lookup_json<'a>(&self, json: &'a serde_json::Value) -> Option<&'a serde_json::Value> {
        self.0.iter().try_fold(json, |v, s| match s {
            Segment::Key(k) => v.get(k),
            Segment::Index(i) => v.get(i),
        })
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.prefix(self.0.len()))
    }
}

/// One `PATH=VALUE` override.
#[derive(Debug, Clone)]
pub struct Override {
    /// The key path.
    pub path: KeyPath,
    /// The value (TOML).
    pub value: Value,
}

impl Override {
    /// Parse `PATH=VALUE` (see the module header).
    ///
    /// # Errors
    /// A [`SceneError`] at the path (or `--set` when there is no path).
    pub fn parse(arg: &str) -> Result<Self, SceneError> {
        let Some((path, raw)) = arg.split_once('=') else {
            return Err(SceneError::new(
                "--set",
                format!("`{arg}` is not PATH=VALUE (e.g. brownian.duration=2.0)"),
            ));
        };
        let path_text = path.trim();
        let path = KeyPath::parse(path_text).map_err(|e| SceneError::new("--set", e))?;
        let value = parse_value(raw.trim())
            .map_err(|e| SceneError::new(path_text, format!("--set {arg}: {e}")))?;
        Ok(Self { path, value })
    }

    /// An override of `path` with `value`.
    pub fn new(path: KeyPath, value: Value) -> Self {
        Self { path, value }
    }

    /// The value as TOML text (`2.0`, `"fire"`).
    pub fn value_text(&self) -> String {
        self.value.clone().decorated("", "").to_string()
    }
}

impl fmt::Display for Override {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.path, self.value_text())
    }
}

/// `raw` as a TOML value; a bare word that is not TOML is a string.
///
/// # Errors
/// Why `raw` is not a value.
pub fn parse_value(raw: &str) -> Result<Value, String> {
    if raw.is_empty() {
        return Err("the value is empty (a string must be quoted: \"\")".into());
    }
    match raw.parse::<Value>() {
        Ok(v) => Ok(v.decorated("", "")),
        Err(e) => {
            let bare = raw
                .chars()
                .all(|c| c.is_alphanumeric() || "_-+.:/@%".contains(c));
            if bare {
                Ok(Value::from(raw))
            } else {
                let first = e.to_string();
                let first = first.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
                Err(format!("`{raw}` is not a TOML value ({first})"))
            }
        }
    }
}

/// `text` with every override applied in order (the text itself when there are none).
///
/// # Errors
/// [`SceneErrors`]: a TOML syntax error of `text` (as [`parse_scene`](super::parse_scene)
/// reports it), or an override that cannot be applied, at its key path.
pub fn apply_overrides(text: &str, overrides: &[Override]) -> Result<String, SceneErrors> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc = parse_document(text)?;
    let errors: Vec<SceneError> = overrides
        .iter()
        .filter_map(|o| apply_to_document(&mut doc, o).err())
        .collect();
    if errors.is_empty() {
        Ok(doc.to_string())
    } else {
        Err(SceneErrors(errors))
    }
}

/// `text` as an editable document.
///
/// # Errors
/// The syntax error, at path `(syntax)`.
pub fn parse_document(text: &str) -> Result<DocumentMut, SceneErrors> {
    text.parse::<DocumentMut>().map_err(|e| {
        SceneErrors(vec![SceneError::new(
            "(syntax)",
            e.to_string().trim().to_string(),
        )])
    })
}

/// The item at `path` in `doc`, if any.
pub fn lookup<'a>(doc: &'a DocumentMut, path: &KeyPath) -> Option<&'a Item> {
    let mut item = doc.as_item();
    for s in &path.0 {
        item = match s {
            Segment::Key(k) => item.get(k.as_str())?,
            Segment::Index(i) => item.get(*i)?,
        };
    }
    Some(item)
}

/// A container reached while walking a path.
enum Node<'a> {
    Table(&'a mut Table),
    Inline(&'a mut InlineTable),
    Tables(&'a mut ArrayOfTables),
    Array(&'a mut toml_edit::Array),
    Leaf(&'static str),
}

fn node(item: &mut Item) -> Node<'_> {
    match item {
        Item::Table(t) => Node::Table(t),
        Item::ArrayOfTables(a) => Node::Tables(a),
        Item::Value(v) => value_node(v),
        Item::None => Node::Leaf("nothing"),
    }
}

fn value_node(v: &mut Value) -> Node<'_> {
    match v {
        Value::InlineTable(t) => Node::Inline(t),
        Value::Array(a) => Node::Array(a),
        other => Node::Leaf(other.type_name()),
    }
}

/// `new` in place of the value `old`, keeping its comments and spacing.
fn keep_decor(old: &Value, mut new: Value) -> Value {
    *new.decor_mut() = old.decor().clone();
    new
}

/// The item that replaces `old` with `new`: a `[table]` stays a table and a `[[table]]`
/// array stays one when the value allows it.
fn replacement(old: Option<&Item>, new: Value) -> Item {
    match (old, new) {
        (Some(Item::Table(_)), Value::InlineTable(t)) => Item::Table(t.into_table()),
        (Some(Item::ArrayOfTables(_)), Value::Array(a))
            if a.iter().all(|v| v.is_inline_table()) =>
        {
            let mut tables = ArrayOfTables::new();
            for v in a {
                if let Value::InlineTable(t) = v {
                    tables.push(t.into_table());
                }
            }
            Item::ArrayOfTables(tables)
        }
        (Some(Item::Value(old)), new) => Item::Value(keep_decor(old, new)),
        (_, new) => Item::Value(new.decorated(" ", "")),
    }
}

/// Apply one override to `doc`.
///
/// # Errors
/// A [`SceneError`] at the path (up to the step that fails).
pub fn apply_to_document(doc: &mut DocumentMut, ov: &Override) -> Result<(), SceneError> {
    let path = &ov.path;
    let n = path.0.len();
    let mut here = Node::Table(doc.as_table_mut());
    for (k, seg) in path.0.iter().enumerate() {
        let last = k + 1 == n;
        let at = || path.prefix(k + 1);
        let fail = |why: String| SceneError::new(at(), format!("--set {ov}: {why}"));
        here = match (here, seg) {
            (Node::Table(t), Segment::Key(key)) => {
                if last {
                    let item = replacement(t.get(key), ov.value.clone());
                    t.insert(key, item);
                    return Ok(());
                }
                if !t.contains_key(key) {
                    t.insert(key, Item::Table(Table::new()));
                }
                node(t.get_mut(key).ok_or_else(|| fail("missing".into()))?)
            }
            (Node::Inline(t), Segment::Key(key)) => {
                if last {
                    let new = match t.get(key) {
                        Some(old) => keep_decor(old, ov.value.clone()),
                        None => ov.value.clone().decorated(" ", " "),
                    };
                    t.insert(key.as_str(), new);
                    return Ok(());
                }
                if !t.contains_key(key) {
                    t.insert(key.as_str(), Value::InlineTable(InlineTable::new()));
                }
                value_node(t.get_mut(key).ok_or_else(|| fail("missing".into()))?)
            }
            (Node::Tables(a), Segment::Index(i)) => {
                let len = a.len();
                let Some(table) = a.get_mut(*i) else {
                    return Err(fail(past_end(*i, len)));
                };
                if last {
                    let Value::InlineTable(t) = ov.value.clone() else {
                        return Err(fail(format!(
                            "an entry of an array of tables must be set to an inline table \
                             {{ ... }}, got a {}",
                            ov.value.type_name()
                        )));
                    };
                    let position = table.position();
                    *table = t.into_table();
                    table.set_position(position);
                    return Ok(());
                }
                Node::Table(table)
            }
            (Node::Array(a), Segment::Index(i)) => {
                let len = a.len();
                let Some(v) = a.get_mut(*i) else {
                    return Err(fail(past_end(*i, len)));
                };
                if last {
                    *v = keep_decor(v, ov.value.clone());
                    return Ok(());
                }
                value_node(v)
            }
            (Node::Tables(_) | Node::Array(_), Segment::Key(_)) => {
                return Err(fail(format!(
                    "`{}` is an array: select an entry with [i]",
                    path.prefix(k)
                )));
            }
            (Node::Table(_) | Node::Inline(_), Segment::Index(_)) => {
                return Err(fail(format!(
                    "`{}` is a table, not an array",
                    path.prefix(k)
                )));
            }
            (Node::Leaf(kind), _) => {
                return Err(fail(format!(
                    "`{}` is a {kind}, not a table or array",
                    path.prefix(k)
                )));
            }
        };
    }
    Ok(())
}

fn past_end(i: usize, len: usize) -> String {
    format!("index {i} is past the end (the array has {len} entries)")
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# a scene\n[simulation]\npipeline = \"packing\" # which\nseed = 1\n\n\
                        [[particles]]\ncount = 3\nshape = { kind = \"sphere\", radius = 0.5 }\n\n\
                        [[particles]]\ncount = 4\nshape = { kind = \"sphere\", radius = 0.25 }\n";

    fn apply(args: &[&str]) -> Result<toml::Table, SceneErrors> {
        let ovs: Vec<Override> = args.iter().map(|a| Override::parse(a).unwrap()).collect();
        let text = apply_overrides(TEXT, &ovs)?;
        Ok(text.parse::<toml::Table>().expect("edited text is TOML"))
    }

    #[test]
    fn paths_parse_and_print_back() {
        for p in ["a", "particles[0].shape.radius", "a.b[1][2].c", "x-y_z.w"] {
            assert_eq!(KeyPath::parse(p).unwrap().to_string(), p);
        }
        for bad in ["", "a..b", "a[", "a[x]", "a[0]b", ".a", "a b", "[0]"] {
            assert!(KeyPath::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn values_are_toml_or_bare_words() {
        assert_eq!(parse_value("2.0").unwrap().as_float(), Some(2.0));
        assert_eq!(parse_value("2").unwrap().as_integer(), Some(2));
        assert_eq!(parse_value("fire").unwrap().as_str(), Some("fire"));
        assert_eq!(parse_value("\"a b\"").unwrap().as_str(), Some("a b"));
        assert!(parse_value("[1, 2").is_err());
        assert!(parse_value("two words").is_err());
        assert!(parse_value("").is_err());
        let t = parse_value("{ kind = \"sphere\", radius = 1 }").unwrap();
        assert!(t.is_inline_table());
    }

    #[test]
    fn overrides_edit_values_keep_comments_and_add_keys() {
        let ovs = [
            Override::parse("simulation.pipeline=fire").unwrap(),
            Override::parse("particles[1].shape.radius=1e-7").unwrap(),
            Override::parse("packing.initial_packing_fraction=0.3").unwrap(),
        ];
        let text = apply_overrides(TEXT, &ovs).unwrap();
        assert!(text.starts_with("# a scene\n"), "{text}");
        assert!(text.contains("pipeline = \"fire\" # which"), "{text}");
        let t: toml::Table = text.parse().unwrap();
        assert_eq!(t["particles"][1]["shape"]["radius"].as_float(), Some(1e-7));
        assert_eq!(t["particles"][0]["shape"]["radius"].as_float(), Some(0.5));
        assert_eq!(
            t["packing"]["initial_packing_fraction"].as_float(),
            Some(0.3)
        );
        // the later of two overrides of one key wins
        let t = apply(&["simulation.seed=2", "simulation.seed=3"]).unwrap();
        assert_eq!(t["simulation"]["seed"].as_integer(), Some(3));
    }

    #[test]
    fn tables_can_be_replaced_whole() {
        let t = apply(&["simulation={ pipeline = \"brownian\", seed = 9 }"]).unwrap();
        assert_eq!(t["simulation"]["seed"].as_integer(), Some(9));
        let t = apply(&["particles[0]={ count = 8, shape = { kind = \"sphere\", radius = 1 } }"])
            .unwrap();
        assert_eq!(t["particles"][0]["count"].as_integer(), Some(8));
        assert_eq!(t["particles"][1]["count"].as_integer(), Some(4));
    }

    #[test]
    fn bad_targets_name_the_path() {
        let cases = [
            ("particles[2].count=1", "particles[2]", "past the end"),
            ("simulation.seed.x=1", "simulation.seed.x", "integer"),
            ("particles.count=1", "particles.count", "is an array"),
            ("simulation[0]=1", "simulation[0]", "is a table"),
            ("particles[0]=3", "particles[0]", "inline table"),
        ];
        for (arg, path, why) in cases {
            let e = apply(&[arg]).unwrap_err();
            assert_eq!(e.0[0].path, path, "{arg}");
            assert!(e.0[0].message.contains(why), "{arg}: {}", e.0[0].message);
        }
        let e = Override::parse("simulation.seed").unwrap_err();
        assert!(e.message.contains("PATH=VALUE"), "{}", e.message);
        let e = Override::parse("simulation.seed=[1,").unwrap_err();
        assert_eq!(e.path, "simulation.seed");
    }

    #[test]
    fn json_lookup_follows_paths() {
        let j = serde_json::json!({"a": {"b": [1, {"c": 2.5}]}});
        let p = KeyPath::parse("a.b[1].c").unwrap();
        assert_eq!(p.lookup_json(&j), Some(&serde_json::json!(2.5)));
        assert!(KeyPath::parse("a.x").unwrap().lookup_json(&j).is_none());
    }
}
