//! Static types, run-time storage cells, interned strings, and the public [`Value`] view.
//!
//! Every datamodel variable and event parameter has a static [`Ty`]. At run
//! time it is stored in a cell; scalars are inline, arrays and structs are
//! lists of cells whose buffers are reused between steps and runs
//! (`clone_from`), so a run in steady state does not allocate.

use std::collections::HashMap;

/// An interned string: an index into the model's string table.
///
/// Every string a model can produce is a literal of the model (there is no
/// string concatenation), so the table is fixed when the model is compiled;
/// [`StrId(0)`](StrId) is the empty string.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct StrId(pub u32);

/// The string interner of a compiled model.
#[derive(Clone, Debug)]
pub struct Strings {
    map: HashMap<Box<str>, u32>,
    list: Vec<Box<str>>,
}

impl Default for Strings {
    fn default() -> Self {
        let mut s = Strings {
            map: HashMap::new(),
            list: Vec::new(),
        };
        s.intern("");
        s
    }
}

impl Strings {
    /// The id of `s`, adding it when new.
    pub fn intern(&mut self, s: &str) -> StrId {
        if let Some(&i) = self.map.get(s) {
            return StrId(i);
        }
        let i = self.list.len() as u32;
        self.list.push(s.into());
        self.map.insert(s.into(), i);
        StrId(i)
    }

    /// The id of `s` when the model contains it.
    pub fn lookup(&self, s: &str) -> Option<StrId> {
        self.map.get(s).map(|&i| StrId(i))
    }

    /// The text of an id (`""` for an unknown id).
    pub fn get(&self, id: StrId) -> &str {
        self.list.get(id.0 as usize).map_or("", |s| s)
    }

    /// Number of strings.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Always false: the empty string is always present.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}

/// A static type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ty {
    /// `bool`.
    Bool,
    /// Every integer width (and enumerations), stored as `i64`.
    Int,
    /// `float32` / `float64`, stored as `f64`.
    Float,
    /// Interned string.
    Str,
    /// Array with an optional maximum length.
    Array(Box<Ty>, Option<u32>),
    /// Struct: index into the model's struct table.
    Struct(u32),
    /// The element type of `[]` before it meets a declared type.
    Unknown,
}

impl Ty {
    /// True for `Int` and `Float`.
    pub(crate) fn is_numeric(&self) -> bool {
        matches!(self, Ty::Int | Ty::Float)
    }
}

/// A struct type from `types.xml`.
#[derive(Clone, Debug)]
pub struct StructDef {
    /// Type name.
    pub name: String,
    /// Fields in declaration order.
    pub fields: Vec<(String, Ty)>,
}

/// Named types available to expressions: structs and enumeration labels.
#[derive(Clone, Debug, Default)]
pub struct TypeTable {
    /// Struct definitions; `Ty::Struct(i)` is `structs[i]`.
    pub structs: Vec<StructDef>,
    /// Enumeration labels and their integer values (globally unique, as in SCAN).
    pub labels: HashMap<String, i64>,
    /// Named types by name.
    pub named: HashMap<String, Ty>,
}

impl TypeTable {
    /// Human-readable type name.
    pub fn name(&self, ty: &Ty) -> String {
        match ty {
            Ty::Bool => "bool".into(),
            Ty::Int => "int".into(),
            Ty::Float => "float".into(),
            Ty::Str => "string".into(),
            Ty::Array(t, None) => format!("{}[]", self.name(t)),
            Ty::Array(t, Some(n)) => format!("{}[{n}]", self.name(t)),
            Ty::Struct(i) => self
                .structs
                .get(*i as usize)
                .map_or_else(|| "struct".into(), |s| s.name.clone()),
            Ty::Unknown => "unknown".into(),
        }
    }

    /// The default (initial) value of a type.
    pub fn default_cell(&self, ty: &Ty) -> Cell {
        match ty {
            Ty::Bool => Cell::Bool(false),
            Ty::Int | Ty::Unknown => Cell::Int(0),
            Ty::Float => Cell::Float(0.0),
            Ty::Str => Cell::Str(StrId(0)),
            Ty::Array(..) => Cell::List(List::default()),
            Ty::Struct(i) => Cell::list(
                self.structs
                    .get(*i as usize)
                    .map(|s| s.fields.iter().map(|(_, t)| self.default_cell(t)).collect())
                    .unwrap_or_default(),
            ),
        }
    }
}

/// Run-time storage of one value. Arrays and structs are lists of cells.
#[derive(Debug, PartialEq)]
pub enum Cell {
    /// A boolean.
    Bool(bool),
    /// An integer of any declared width.
    Int(i64),
    /// A float of either declared width.
    Float(f64),
    /// An interned string.
    Str(StrId),
    /// An array, or a struct's fields in declaration order.
    List(List),
}

impl Cell {
    /// A list cell holding `items`.
    pub fn list(items: Vec<Cell>) -> Cell {
        Cell::List(List::from(items))
    }
}

impl Clone for Cell {
    fn clone(&self) -> Self {
        match self {
            Cell::Bool(b) => Cell::Bool(*b),
            Cell::Int(v) => Cell::Int(*v),
            Cell::Float(v) => Cell::Float(*v),
            Cell::Str(s) => Cell::Str(*s),
            Cell::List(v) => Cell::List(v.clone()),
        }
    }

    /// Reuses the destination's buffers (list into list, element by element), so copying
    /// a value into a cell of the same shape does not allocate.
    fn clone_from(&mut self, source: &Self) {
        match (self, source) {
            (Cell::List(dst), Cell::List(src)) => dst.assign(src),
            (dst, src) => *dst = src.clone(),
        }
    }
}

/// Copies `src` into `dst` as `Vec::clone_from` does (the result is equal to `src`, and
/// lists reuse their buffers), with scalars of the same kind copied in place: a message's
/// parameters are mostly numbers, and this is the copy each receiver of an AS2FM message
/// makes (the generic path dropped and rebuilt every cell).
#[inline]
pub fn assign_cells(dst: &mut Vec<Cell>, src: &[Cell]) {
    dst.truncate(src.len());
    let kept = dst.len();
    for (d, s) in dst.iter_mut().zip(src) {
        match (d, s) {
            (Cell::Int(a), Cell::Int(b)) => *a = *b,
            (Cell::Float(a), Cell::Float(b)) => *a = *b,
            (Cell::Bool(a), Cell::Bool(b)) => *a = *b,
            (Cell::Str(a), Cell::Str(b)) => *a = *b,
            (d, s) => d.clone_from(s),
        }
    }
    dst.extend_from_slice(&src[kept..]);
}

/// The elements of an array or the fields of a struct.
///
/// Elements removed by shrinking stay in the buffer past the live length, buffers and all,
/// and are reused when the list grows again: an array of arrays or structs that a run
/// empties and refills (or that messages of different lengths pass through) does not
/// allocate once it has been as long before. Reads see only the live elements (the list
/// derefs to a slice of them).
#[derive(Default)]
pub struct List {
    /// Live elements first, then set-aside ones.
    items: Vec<Cell>,
    /// Number of live elements (at most `items.len()`).
    len: usize,
}

impl From<Vec<Cell>> for List {
    fn from(items: Vec<Cell>) -> Self {
        let len = items.len();
        List { items, len }
    }
}

impl Clone for List {
    fn clone(&self) -> Self {
        List::from(self.to_vec())
    }
}

impl PartialEq for List {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl std::fmt::Debug for List {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl std::ops::Deref for List {
    type Target = [Cell];
    fn deref(&self) -> &[Cell] {
        self.items.get(..self.len).unwrap_or(&[])
    }
}

impl std::ops::DerefMut for List {
    fn deref_mut(&mut self) -> &mut [Cell] {
        let len = self.len.min(self.items.len());
        &mut self.items[..len]
    }
}

impl List {
    /// Keeps the first `n` elements; the others are set aside for reuse.
    pub fn truncate(&mut self, n: usize) {
        self.len = self.len.min(n);
    }

    /// Appends a copy of `value`, into a set-aside element when there is one.
    pub(crate) fn push_copy(&mut self, value: &Cell) {
        match self.items.get_mut(self.len) {
            Some(c) => c.clone_from(value),
            None => self.items.push(value.clone()),
        }
        self.len += 1;
    }

    /// Grows to `n` elements with whatever set-aside elements hold (each is overwritten
    /// by the caller), then `Int(0)`s; or shrinks to `n`.
    pub(crate) fn set_len(&mut self, n: usize) {
        while self.items.len() < n {
            self.items.push(Cell::Int(0));
        }
        self.len = n;
    }

    /// Shrinks to `n`, or grows to `n` with copies of `fill`.
    pub fn resize(&mut self, n: usize, fill: &Cell) {
        self.truncate(n);
        while self.len < n {
            self.push_copy(fill);
        }
    }

    /// Becomes a copy of `src`, reusing its own elements' buffers.
    pub fn assign(&mut self, src: &List) {
        self.truncate(src.len());
        let live = self.len;
        for (d, s) in self.iter_mut().zip(src.iter()) {
            d.clone_from(s);
        }
        for s in src.iter().skip(live) {
            self.push_copy(s);
        }
    }
}

/// A read-only view of a value produced by a run (a message parameter, a logged value).
///
/// Strings are [`StrId`]s, resolved with the compiled model's string table;
/// arrays and structs are [`Value::List`]s (a struct lists its fields in
/// declaration order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value<'a> {
    /// A boolean.
    Bool(bool),
    /// An integer (every integer width and enumerations).
    Int(i64),
    /// A float (`float32` and `float64`).
    Float(f64),
    /// An interned string.
    Str(StrId),
    /// An array or a struct.
    List(ListRef<'a>),
}

/// The elements of an array (or fields of a struct) in a [`Value::List`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ListRef<'a>(pub &'a [Cell]);

impl<'a> ListRef<'a> {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when there is no element.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Element `i`.
    pub fn get(&self, i: usize) -> Option<Value<'a>> {
        self.0.get(i).map(Value::of)
    }

    /// All elements in order.
    pub fn iter(&self) -> impl Iterator<Item = Value<'a>> + 'a {
        self.0.iter().map(Value::of)
    }
}

impl<'a> Value<'a> {
    /// A view of a cell.
    pub fn of(c: &'a Cell) -> Value<'a> {
        match c {
            Cell::Bool(b) => Value::Bool(*b),
            Cell::Int(v) => Value::Int(*v),
            Cell::Float(v) => Value::Float(*v),
            Cell::Str(s) => Value::Str(*s),
            Cell::List(v) => Value::List(ListRef(v)),
        }
    }

    /// The integer, if this is one.
    pub fn as_i64(&self) -> Option<i64> {
        match self {
            Value::Int(v) => Some(*v),
            _ => None,
        }
    }

    /// The number as a float, if this is an integer or a float.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Int(v) => Some(*v as f64),
            Value::Float(v) => Some(*v),
            _ => None,
        }
    }

    /// The string id, if this is a string.
    pub fn as_str_id(&self) -> Option<StrId> {
        match self {
            Value::Str(s) => Some(*s),
            _ => None,
        }
    }

    /// Writes the value as text (strings resolved, lists as `[a,b]`).
    pub fn write_to(&self, strings: &Strings, out: &mut String) {
        use std::fmt::Write;
        match self {
            Value::Bool(b) => {
                let _ = write!(out, "{b}");
            }
            Value::Int(v) => {
                let _ = write!(out, "{v}");
            }
            Value::Float(v) => {
                let _ = write!(out, "{v}");
            }
            Value::Str(s) => out.push_str(strings.get(*s)),
            Value::List(l) => write_list(l.iter(), out, |v, out| v.write_to(strings, out)),
        }
    }
}

/// Writes `items` as `[a,b]`, each by `write`.
fn write_list<T>(items: impl Iterator<Item = T>, out: &mut String, write: impl Fn(T, &mut String)) {
    out.push('[');
    for (i, v) in items.enumerate() {
        if i > 0 {
            out.push(',');
        }
        write(v, out);
    }
    out.push(']');
}

/// An owned copy of a [`Value`], for traces kept after the run.
#[derive(Clone, Debug, PartialEq)]
pub enum OwnedValue {
    /// A boolean.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float.
    Float(f64),
    /// An interned string.
    Str(StrId),
    /// An array or struct.
    List(Vec<OwnedValue>),
}

impl From<Value<'_>> for OwnedValue {
    fn from(v: Value<'_>) -> Self {
        match v {
            Value::Bool(b) => OwnedValue::Bool(b),
            Value::Int(i) => OwnedValue::Int(i),
            Value::Float(f) => OwnedValue::Float(f),
            Value::Str(s) => OwnedValue::Str(s),
            Value::List(l) => OwnedValue::List(l.iter().map(OwnedValue::from).collect()),
        }
    }
}

impl OwnedValue {
    /// Writes the value as text, as [`Value::write_to`] does.
    pub fn write_to(&self, strings: &Strings, out: &mut String) {
        match self {
            OwnedValue::Bool(b) => Value::Bool(*b).write_to(strings, out),
            OwnedValue::Int(v) => Value::Int(*v).write_to(strings, out),
            OwnedValue::Float(v) => Value::Float(*v).write_to(strings, out),
            OwnedValue::Str(s) => Value::Str(*s).write_to(strings, out),
            OwnedValue::List(l) => write_list(l.iter(), out, |v, out| v.write_to(strings, out)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assign_cells_copies_every_kind_and_length() {
        let list = |n: i64| Cell::list((0..n).map(Cell::Int).collect());
        let src = vec![
            Cell::Int(-4),
            Cell::Float(2.5),
            Cell::Bool(true),
            Cell::Str(StrId(3)),
            list(3),
        ];
        // Same kinds, other kinds in every position, shorter and longer destinations.
        let dsts = [
            vec![
                Cell::Int(0),
                Cell::Float(0.0),
                Cell::Bool(false),
                Cell::Str(StrId(0)),
                list(1),
            ],
            vec![
                list(2),
                Cell::Int(1),
                Cell::Str(StrId(9)),
                Cell::Float(1.0),
                Cell::Bool(true),
            ],
            vec![Cell::Int(7)],
            vec![Cell::Int(7); 8],
            Vec::new(),
        ];
        for mut dst in dsts {
            assign_cells(&mut dst, &src);
            assert_eq!(dst, src);
        }
    }

    #[test]
    fn lists_reuse_the_elements_they_shrink_away() {
        let inner = |n: i64| Cell::list((0..n).map(Cell::Int).collect());
        let mut l = List::from(vec![inner(3), inner(4)]);
        l.truncate(0);
        assert!(l.is_empty());
        assert_eq!(l, List::default());
        assert_eq!(format!("{l:?}"), "[]");
        // The set-aside element keeps its buffer: refilling it in place allocates nothing.
        let before = match &l.items[0] {
            Cell::List(v) => v.items.as_ptr(),
            _ => unreachable!(),
        };
        l.push_copy(&inner(2));
        assert_eq!(l.len(), 1);
        assert_eq!(l[0], inner(2));
        match &l[0] {
            Cell::List(v) => assert_eq!(v.items.as_ptr(), before),
            _ => unreachable!(),
        }
        l.resize(3, &Cell::Int(7));
        assert_eq!(*l, [inner(2), Cell::Int(7), Cell::Int(7)]);
        let mut m = List::from(vec![Cell::Int(1)]);
        m.assign(&l);
        assert_eq!(m, l);
        l.set_len(1);
        m.assign(&l);
        assert_eq!(m.len(), 1);
        assert_eq!(m.clone(), l);
        // A cell stays small: every variable and parameter is one.
        assert!(
            std::mem::size_of::<Cell>() <= 32,
            "{}",
            std::mem::size_of::<Cell>()
        );
    }
}
