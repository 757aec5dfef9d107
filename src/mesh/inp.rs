//! CalculiX / Abaqus input decks (`.inp`): the mesh part.
//!
//! Read: `*NODE` (optionally `NSET=`), `*ELEMENT` of the 8-node brick family (`C3D8`,
//! `C3D8R`, `C3D8I`, `C3D8H`, `C3D8RH`, `C3D8IH`: the node order is tribo's VTK order; all
//! become tribo's hexahedron, whose integration is tribo's own F-bar rule whatever the
//! deck's suffix says), `*NSET` and `*ELSET` (lists of labels or of earlier set names, or
//! `GENERATE` triples first, last[, step]), element-face `*SURFACE` (`TYPE=ELEMENT`, data
//! `element or element set, S1..S6`), `*INCLUDE, INPUT=file` (resolved by the caller's
//! read policy, relative to the including file), `*HEADING` and `**` comments. Any other
//! keyword, element type or surface type is refused with file:line and the keyword: decks
//! with a material, steps or boundary conditions keep their mesh in an `*INCLUDE`d file,
//! which is what to give tribo.
//!
//! Sets become tribo's sets of the same name: `*NSET` a node set, `*ELSET` an element set,
//! `*SURFACE` a face set and, unless an `*NSET` of that name exists, a node set of its
//! faces' nodes. Names are matched without regard to case, as Abaqus does, and kept as
//! first written. Labels may come in any order; a data line may continue on the next when
//! it ends with a comma. Cost: O(file size).

use std::collections::{BTreeMap, HashMap};

use super::import::{FileFace, Imported};
use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};

/// Brick element types read as tribo's 8-node hexahedron.
pub const HEXAHEDRON_TYPES: [&str; 6] = ["C3D8", "C3D8R", "C3D8I", "C3D8H", "C3D8RH", "C3D8IH"];

/// Abaqus faces S1..S6 of a C3D8 as indices into [`super::HEX_FACES`]: S1 = nodes 1234
/// (zeta = -1), S2 = 5876 (zeta = +1), S3 = 1562 (eta = -1), S4 = 2673 (xi = +1),
/// S5 = 3784 (eta = +1), S6 = 4851 (xi = -1).
const ABAQUS_FACE: [usize; 6] = [4, 5, 2, 1, 3, 0];

/// Deepest `*INCLUDE` nesting (a file including itself stops here).
const MAX_INCLUDE_DEPTH: usize = 16;

/// Reads the file `includer` named `given` (relative to the includer's folder): returns the
/// name to use in messages and the text.
pub type IncludeReader<'a> = dyn FnMut(&str, &str) -> Result<(String, String)> + 'a;

/// Reads a deck whose text is `text`; `file` names it in messages and is the includer of
/// its `*INCLUDE`s, read through `include`.
pub fn read_inp(text: &str, file: &str, include: &mut IncludeReader) -> Result<Mesh> {
    let mut deck = Deck::default();
    deck.read(text, file, include, 0)?;
    deck.finish(file)
}

#[derive(Default)]
struct Deck {
    nodes: Vec<Vec3>,
    node_label: HashMap<i64, usize>,
    /// Element labels, nodes (labels) and where each is defined.
    elements: Vec<(i64, [i64; 8], String)>,
    node_sets: Named<i64>,
    element_sets: Named<i64>,
    surfaces: Named<(i64, usize)>,
}

/// Named lists with the place of their first definition, names without regard to case.
struct Named<T> {
    sets: BTreeMap<String, (Vec<T>, String)>,
}

impl<T> Default for Named<T> {
    fn default() -> Self {
        Named {
            sets: BTreeMap::new(),
        }
    }
}

impl<T: Clone> Named<T> {
    fn key(&self, name: &str) -> Option<String> {
        if self.sets.contains_key(name) {
            return Some(name.to_string());
        }
        self.sets
            .keys()
            .find(|k| k.eq_ignore_ascii_case(name))
            .cloned()
    }
    fn entry(&mut self, name: &str, at: &str) -> &mut Vec<T> {
        let key = self.key(name).unwrap_or_else(|| name.to_string());
        &mut self
            .sets
            .entry(key)
            .or_insert_with(|| (Vec::new(), at.to_string()))
            .0
    }
    fn get(&self, name: &str) -> Option<&Vec<T>> {
        self.key(name).map(|k| &self.sets[&k].0)
    }
}

/// What the data lines after the current keyword are.
enum Block {
    None,
    Skip,
    Node(Option<String>),
    Element(Option<String>),
    Nset(String, bool),
    Elset(String, bool),
    Surface(String),
}

/// A keyword line: the keyword (upper case, without `*`) and its parameters (keys upper
/// case, values as written).
struct Keyword {
    name: String,
    params: Vec<(String, Option<String>)>,
}

impl Keyword {
    fn parse(line: &str) -> Keyword {
        let mut parts = line[1..].split(',');
        let name = parts.next().unwrap_or("").trim().to_ascii_uppercase();
        let params = parts
            .filter(|p| !p.trim().is_empty())
            .map(|p| match p.split_once('=') {
                Some((k, v)) => (k.trim().to_ascii_uppercase(), Some(v.trim().to_string())),
                None => (p.trim().to_ascii_uppercase(), None),
            })
            .collect();
        Keyword { name, params }
    }
    fn value(&self, key: &str) -> Option<&str> {
        self.params
            .iter()
            .find(|(k, _)| k == key)
            .and_then(|(_, v)| v.as_deref())
    }
    fn flag(&self, key: &str) -> bool {
        self.params.iter().any(|(k, _)| k == key)
    }
    /// Refuses parameters other than `allowed`.
    fn only(&self, allowed: &[&str], at: &str) -> Result<()> {
        match self
            .params
            .iter()
            .find(|(k, _)| !allowed.contains(&k.as_str()))
        {
            Some((k, _)) => Err(Error::Input(format!(
                "{at}: *{}: parameter {k} is not supported (supported: {})",
                self.name,
                if allowed.is_empty() {
                    "none".to_string()
                } else {
                    allowed.join(", ")
                }
            ))),
            None => Ok(()),
        }
    }
    fn required(&self, key: &str, at: &str) -> Result<String> {
        self.value(key)
            .map(str::to_string)
            .ok_or_else(|| Error::Input(format!("{at}: *{} needs {key}=", self.name)))
    }
}

fn int(token: &str, what: &str, at: &str) -> Result<i64> {
    token
        .parse::<i64>()
        .map_err(|_| Error::Input(format!("{at}: {what} {token:?} is not an integer")))
}

fn real(token: &str, what: &str, at: &str) -> Result<f64> {
    let v = token
        .replace(['d', 'D'], "e")
        .parse::<f64>()
        .map_err(|_| Error::Input(format!("{at}: {what} {token:?} is not a number")))?;
    if !v.is_finite() {
        return Err(Error::Input(format!(
            "{at}: {what} {token:?} must be finite"
        )));
    }
    Ok(v)
}

/// `first, last[, step]` of a GENERATE line.
fn generate(tokens: &[&str], at: &str) -> Result<Vec<i64>> {
    if !(2..=3).contains(&tokens.len()) {
        return Err(Error::Input(format!(
            "{at}: a GENERATE line must be `first, last[, step]`"
        )));
    }
    let first = int(tokens[0], "first label", at)?;
    let last = int(tokens[1], "last label", at)?;
    let step = if tokens.len() == 3 {
        int(tokens[2], "step", at)?
    } else {
        1
    };
    if step <= 0 || last < first || (last - first) / step > 50_000_000 {
        return Err(Error::Input(format!(
            "{at}: GENERATE {first}, {last}, {step} must have step > 0 and last >= first"
        )));
    }
    Ok((first..=last).step_by(step as usize).collect())
}

impl Deck {
    fn read(
        &mut self,
        text: &str,
        file: &str,
        include: &mut IncludeReader,
        depth: usize,
    ) -> Result<()> {
        let mut block = Block::None;
        let mut pending: Vec<String> = Vec::new();
        let mut pending_at = String::new();
        for (i, raw) in text.lines().enumerate() {
            let at = format!("{file}:{}", i + 1);
            let line = raw.trim();
            if line.is_empty() || line.starts_with("**") {
                continue;
            }
            if line.starts_with('*') {
                if !pending.is_empty() {
                    return Err(Error::Input(format!(
                        "{pending_at}: the element's node list ends with a comma but no data line follows"
                    )));
                }
                block = self.keyword(&Keyword::parse(line), &at, file, include, depth)?;
                continue;
            }
            // Data line, possibly continued on the next line when it ends with a comma.
            if pending.is_empty() {
                pending_at = at.clone();
            }
            let continued = line.ends_with(',');
            pending.extend(
                line.split(',')
                    .map(str::trim)
                    .filter(|t| !t.is_empty())
                    .map(str::to_string),
            );
            // Only an element's node list continues on the next line; set lists often end
            // with a comma that continues nothing.
            if continued && matches!(block, Block::Element(_)) && pending.len() < 9 {
                continue;
            }
            let tokens: Vec<&str> = pending.iter().map(String::as_str).collect();
            self.data(&block, &tokens, &pending_at)?;
            pending.clear();
        }
        if !pending.is_empty() {
            return Err(Error::Input(format!(
                "{pending_at}: the element's node list ends with a comma but the file ends"
            )));
        }
        Ok(())
    }

    fn keyword(
        &mut self,
        kw: &Keyword,
        at: &str,
        file: &str,
        include: &mut IncludeReader,
        depth: usize,
    ) -> Result<Block> {
        Ok(match kw.name.as_str() {
            "HEADING" => Block::Skip,
            "NODE" => {
                kw.only(&["NSET"], at)?;
                Block::Node(kw.value("NSET").map(str::to_string))
            }
            "ELEMENT" => {
                kw.only(&["TYPE", "ELSET"], at)?;
                let ty = kw.required("TYPE", at)?;
                if !HEXAHEDRON_TYPES.iter().any(|t| t.eq_ignore_ascii_case(&ty)) {
                    return Err(Error::Input(format!(
                        "{at}: *ELEMENT, TYPE={ty}: element type not supported (tribo meshes \
                         are 8-node hexahedra: {})",
                        HEXAHEDRON_TYPES.join(", ")
                    )));
                }
                Block::Element(kw.value("ELSET").map(str::to_string))
            }
            "NSET" => {
                kw.only(&["NSET", "GENERATE"], at)?;
                let name = kw.required("NSET", at)?;
                self.node_sets.entry(&name, at);
                Block::Nset(name, kw.flag("GENERATE"))
            }
            "ELSET" => {
                kw.only(&["ELSET", "GENERATE"], at)?;
                let name = kw.required("ELSET", at)?;
                self.element_sets.entry(&name, at);
                Block::Elset(name, kw.flag("GENERATE"))
            }
            "SURFACE" => {
                kw.only(&["NAME", "TYPE"], at)?;
                if let Some(ty) = kw.value("TYPE") {
                    if !ty.eq_ignore_ascii_case("ELEMENT") {
                        return Err(Error::Input(format!(
                            "{at}: *SURFACE, TYPE={ty}: only element-face surfaces \
                             (TYPE=ELEMENT) are supported"
                        )));
                    }
                }
                let name = kw.required("NAME", at)?;
                self.surfaces.entry(&name, at);
                Block::Surface(name)
            }
            "INCLUDE" => {
                kw.only(&["INPUT"], at)?;
                let given = kw.required("INPUT", at)?;
                let given = given.trim_matches('"');
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(Error::Input(format!(
                        "{at}: *INCLUDE nested more than {MAX_INCLUDE_DEPTH} deep (a file \
                         including itself?)"
                    )));
                }
                let included_here = |e: Error| match e {
                    Error::Input(m) => Error::Input(format!("{m} (included at {at})")),
                    other => other,
                };
                let (name, text) = include(given, file).map_err(included_here)?;
                self.read(&text, &name, include, depth + 1)
                    .map_err(included_here)?;
                Block::None
            }
            other => {
                return Err(Error::Input(format!(
                    "{at}: keyword *{other} is not supported (tribo reads the mesh of a deck: \
                     *NODE, *ELEMENT, *NSET, *ELSET, *SURFACE, *INCLUDE, *HEADING; keep the \
                     mesh in its own file and *INCLUDE it from the analysis deck)"
                )))
            }
        })
    }

    fn data(&mut self, block: &Block, t: &[&str], at: &str) -> Result<()> {
        match block {
            Block::None => {
                return Err(Error::Input(format!(
                    "{at}: a data line outside any keyword block"
                )))
            }
            Block::Skip => {}
            Block::Node(nset) => {
                if !(3..=4).contains(&t.len()) {
                    return Err(Error::Input(format!(
                        "{at}: *NODE data must be `label, x, y[, z]` ({} entries)",
                        t.len()
                    )));
                }
                let label = int(t[0], "node label", at)?;
                let mut x = [0.0; 3];
                for (k, tok) in t[1..].iter().enumerate() {
                    x[k] = real(tok, "node coordinate", at)?;
                }
                if self.node_label.insert(label, self.nodes.len()).is_some() {
                    return Err(Error::Input(format!("{at}: node {label} is defined twice")));
                }
                self.nodes.push(Vec3::new(x[0], x[1], x[2]));
                if let Some(name) = nset {
                    self.node_sets.entry(name, at).push(label);
                }
            }
            Block::Element(elset) => {
                if t.len() != 9 {
                    return Err(Error::Input(format!(
                        "{at}: *ELEMENT data must be the label and 8 node labels ({} entries)",
                        t.len()
                    )));
                }
                let label = int(t[0], "element label", at)?;
                let mut nodes = [0i64; 8];
                for k in 0..8 {
                    nodes[k] = int(t[k + 1], "node label", at)?;
                }
                self.elements.push((label, nodes, at.to_string()));
                if let Some(name) = elset {
                    self.element_sets.entry(name, at).push(label);
                }
            }
            Block::Nset(name, gen) | Block::Elset(name, gen) => {
                let is_node = matches!(block, Block::Nset(..));
                let labels = if *gen {
                    generate(t, at)?
                } else {
                    let mut labels = Vec::new();
                    for tok in t {
                        match tok.parse::<i64>() {
                            Ok(l) => labels.push(l),
                            Err(_) => {
                                let named = if is_node {
                                    self.node_sets.get(tok)
                                } else {
                                    self.element_sets.get(tok)
                                };
                                let set = named.ok_or_else(|| {
                                    Error::Input(format!(
                                        "{at}: {tok:?} is neither a label nor a {} set defined \
                                         above",
                                        if is_node { "node" } else { "element" }
                                    ))
                                })?;
                                labels.extend(set.clone());
                            }
                        }
                    }
                    labels
                };
                let sets = if is_node {
                    &mut self.node_sets
                } else {
                    &mut self.element_sets
                };
                sets.entry(name, at).extend(labels);
            }
            Block::Surface(name) => {
                if t.len() != 2 {
                    return Err(Error::Input(format!(
                        "{at}: *SURFACE data must be `element or element set, S1..S6`"
                    )));
                }
                let face = t[1]
                    .to_ascii_uppercase()
                    .strip_prefix('S')
                    .and_then(|k| k.parse::<usize>().ok())
                    .filter(|k| (1..=6).contains(k))
                    .ok_or_else(|| {
                        Error::Input(format!(
                            "{at}: face {:?} must be one of S1 .. S6 (faces of a C3D8)",
                            t[1]
                        ))
                    })?;
                let local = ABAQUS_FACE[face - 1];
                let elements = match t[0].parse::<i64>() {
                    Ok(l) => vec![l],
                    Err(_) => self.element_sets.get(t[0]).cloned().ok_or_else(|| {
                        Error::Input(format!(
                            "{at}: {:?} is neither an element label nor an element set defined \
                             above",
                            t[0]
                        ))
                    })?,
                };
                self.surfaces
                    .entry(name, at)
                    .extend(elements.into_iter().map(|e| (e, local)));
            }
        }
        Ok(())
    }

    fn finish(self, file: &str) -> Result<Mesh> {
        let mut out = Imported {
            nodes: self.nodes,
            ..Imported::default()
        };
        let mut element_index = HashMap::new();
        for (label, nodes, at) in &self.elements {
            if element_index.insert(*label, out.hexes.len()).is_some() {
                return Err(Error::Input(format!(
                    "{at}: element {label} is defined twice"
                )));
            }
            let mut hex = [0; 8];
            for k in 0..8 {
                hex[k] = *self.node_label.get(&nodes[k]).ok_or_else(|| {
                    Error::Input(format!(
                        "{at}: element {label} names node {}, which the deck does not define",
                        nodes[k]
                    ))
                })?;
            }
            out.hexes.push(hex);
            out.hex_origin.push(format!("{at}: element {label}"));
        }
        let unknown = |kind: &str, name: &str, origin: &str, label: i64| {
            Error::Input(format!(
                "{origin}: {kind} set {name:?} names {kind} {label}, which the deck does not define"
            ))
        };
        for (name, (labels, origin)) in &self.node_sets.sets {
            let set = labels
                .iter()
                .map(|l| {
                    self.node_label
                        .get(l)
                        .copied()
                        .ok_or_else(|| unknown("node", name, origin, *l))
                })
                .collect::<Result<Vec<_>>>()?;
            out.node_sets.insert(name.clone(), set);
        }
        for (name, (labels, origin)) in &self.element_sets.sets {
            let set = labels
                .iter()
                .map(|l| {
                    element_index
                        .get(l)
                        .copied()
                        .ok_or_else(|| unknown("element", name, origin, *l))
                })
                .collect::<Result<Vec<_>>>()?;
            out.element_sets.insert(name.clone(), set);
        }
        for (name, (faces, origin)) in &self.surfaces.sets {
            let set = faces
                .iter()
                .map(|(l, f)| {
                    element_index
                        .get(l)
                        .map(|&e| FileFace::Element(e, *f))
                        .ok_or_else(|| unknown("element", name, origin, *l))
                })
                .collect::<Result<Vec<_>>>()?;
            // An *NSET of the same name (any case) keeps its own nodes.
            let name = self.node_sets.key(name).unwrap_or_else(|| name.clone());
            out.face_sets.insert(name, (set, origin.clone()));
        }
        out.build(file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_include(given: &str, _: &str) -> Result<(String, String)> {
        Err(Error::Input(format!("{given}: no includes here")))
    }

    fn read(text: &str) -> Result<Mesh> {
        read_inp(text, "deck.inp", &mut no_include)
    }

    const CUBE: &str = "*HEADING\nunit cube\n** comment\n*NODE, NSET=ALL\n1, 0, 0, 0\n2, 1, 0, 0\n\
        3, 1, 1, 0\n4, 0, 1, 0\n5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n99, 5, 5, 5\n\
        *ELEMENT, TYPE=C3D8R, ELSET=BLANK\n10, 1, 2, 3, 4,\n 5, 6, 7, 8\n\
        *NSET, NSET=BOTTOM, GENERATE\n1, 4\n*ELSET, ELSET=E2\nBLANK\n\
        *SURFACE, NAME=TOP\nE2, S2\n*NSET, NSET=Ref\n99\n";

    #[test]
    fn a_cube_with_sets_surfaces_and_a_reference_node() {
        let m = read(CUBE).unwrap();
        // Node 99 is used by no element: dropped, and dropped from the sets.
        assert_eq!(m.node_count(), 8);
        assert_eq!(m.node_set("ALL").unwrap().len(), 8);
        assert!(m.node_set("Ref").unwrap().is_empty());
        assert_eq!(m.node_set("BOTTOM").unwrap(), &[0, 1, 2, 3]);
        assert_eq!(m.element_set("E2").unwrap(), &[0]);
        assert_eq!(m.face_set("TOP").unwrap(), &[[4, 5, 6, 7]]);
        assert_eq!(m.node_set("TOP").unwrap(), &[4, 5, 6, 7]);
    }

    #[test]
    fn faces_s1_to_s6_are_the_abaqus_faces() {
        let nodes = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
        let mut deck = String::from("*NODE\n");
        for (i, x) in nodes.nodes.iter().enumerate() {
            deck.push_str(&format!("{}, {}, {}, {}\n", i + 1, x.x, x.y, x.z));
        }
        // block() numbers (i, j, k) with i fastest: C3D8 order 1 2 4 3 5 6 8 7.
        deck.push_str("*ELEMENT, TYPE=C3D8\n1, 1, 2, 4, 3, 5, 6, 8, 7\n");
        for s in 1..=6 {
            deck.push_str(&format!("*SURFACE, NAME=F{s}\n1, S{s}\n"));
        }
        let m = read(&deck).unwrap();
        // Abaqus: S1 bottom (z = 0), S2 top, S3 y = 0, S4 x = 1, S5 y = 1, S6 x = 0.
        let expect = [(2, 0.0), (2, 1.0), (1, 0.0), (0, 1.0), (1, 1.0), (0, 0.0)];
        for (s, (axis, value)) in expect.iter().enumerate() {
            let q = m.face_set(&format!("F{}", s + 1)).unwrap()[0];
            let x = q.map(|n| m.nodes[n]);
            assert!(x.iter().all(|p| p[*axis] == *value), "S{}", s + 1);
            let normal = (x[1] - x[0]).cross(&(x[3] - x[0]));
            let outward = if *value == 0.0 { -1.0 } else { 1.0 };
            assert!(
                normal[*axis] * outward > 0.0,
                "S{} normal {normal:?}",
                s + 1
            );
        }
    }

    #[test]
    fn unsupported_input_names_file_line_and_keyword() {
        let cases = [
            (
                "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=C3D20R\n",
                "deck.inp:3",
                "C3D20R",
            ),
            (
                "*NODE\n1, 0, 0, 0\n\n*MATERIAL, NAME=STEEL\n",
                "deck.inp:4",
                "*MATERIAL",
            ),
            ("*NODE, SYSTEM=C\n", "deck.inp:1", "SYSTEM"),
            ("*SURFACE, NAME=S, TYPE=NODE\n", "deck.inp:1", "TYPE=NODE"),
            ("*NODE\n1, 0, x, 0\n", "deck.inp:2", "\"x\""),
            ("*NODE\n1, 0, 0, 0\n1, 0, 0, 0\n", "deck.inp:3", "twice"),
            ("*ELSET, ELSET=A\nNOPE\n", "deck.inp:2", "NOPE"),
            ("*NSET, NSET=A, GENERATE\n5, 1\n", "deck.inp:2", "GENERATE"),
            ("*INCLUDE, INPUT=mesh.inp\n", "deck.inp:1", "no includes"),
            (
                "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 8\n",
                "deck.inp:2",
                "node 1",
            ),
        ];
        for (text, at, what) in cases {
            let e = read(text).unwrap_err().to_string();
            assert!(e.contains(at) && e.contains(what), "{text:?}: {e}");
        }
        // An element numbered inside out everywhere is mirrored; a twisted one is refused.
        let mirrored = CUBE.replace("10, 1, 2, 3, 4,\n 5, 6, 7, 8", "10, 5, 6, 7, 8, 1, 2, 3, 4");
        assert_eq!(read(&mirrored).unwrap().hexes[0], [0, 1, 2, 3, 4, 5, 6, 7]);
        let twisted = CUBE.replace("10, 1, 2, 3, 4,\n 5, 6, 7, 8", "10, 1, 2, 4, 3, 5, 6, 7, 8");
        let e = read(&twisted).unwrap_err().to_string();
        assert!(e.contains("deck.inp:15: element 10"), "{e}");
    }

    #[test]
    fn includes_are_read_through_the_callback_and_cycles_stop() {
        let mut calls = Vec::new();
        let mut reader = |given: &str, from: &str| -> Result<(String, String)> {
            calls.push(format!("{from}->{given}"));
            if given == "nodes.inp" {
                Ok(("nodes.inp".into(), CUBE.to_string()))
            } else {
                Ok((given.to_string(), "*INCLUDE, INPUT=self.inp\n".to_string()))
            }
        };
        let m = read_inp("*INCLUDE, INPUT=nodes.inp\n", "main.inp", &mut reader).unwrap();
        assert_eq!(m.element_count(), 1);
        let e = read_inp("*INCLUDE, INPUT=self.inp\n", "main.inp", &mut reader)
            .unwrap_err()
            .to_string();
        assert!(e.contains("self.inp:1") && e.contains("nested"), "{e}");
        assert_eq!(calls[0], "main.inp->nodes.inp");
    }
}
