//! Declared data types: `<!-- TYPE name:type -->` annotations and SCAN's `types.xml` (`<dataTypeList>`).

use super::source::{Diagnostic, FileId, SourceMap, Span};
use super::xml::{self, Node};
pub use codegen::scalar::Scalar;
use codegen::scalar::ScalarKind;

/// A base (scalar) type as written in a model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseType {
    /// `bool` / `boolean`.
    Bool,
    /// `int8` ... `int64`, `uint8` ... `uint64`, `int`: stored as `i64`.
    Int,
    /// `float32`, `float64`, `double`, `float`, `f64`: stored as `f64`.
    Float,
    /// `string` / `URI`: interned strings.
    Str,
}

/// How the simulator stores a scalar.
impl From<Scalar> for BaseType {
    fn from(s: Scalar) -> BaseType {
        match s.kind() {
            ScalarKind::Bool => BaseType::Bool,
            ScalarKind::Int => BaseType::Int,
            ScalarKind::Float => BaseType::Float,
            ScalarKind::Str => BaseType::Str,
        }
    }
}

/// A type expression: a base type, a named type from `types.xml`, or an array of either.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TypeExpr {
    /// A scalar.
    Base(BaseType),
    /// A struct or enumeration declared in `types.xml`.
    Named(String),
    /// An array with an optional maximum length (`int32[6]`); `int32[][]` nests.
    Array(Box<TypeExpr>, Option<u32>),
}

/// Why a type name does not parse; each quotes the text and displays as one sentence.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TypeError {
    /// Nothing before the dimensions (`[3]`).
    MissingName(String),
    /// A base name with characters no type name has.
    NotATypeName(String),
    /// Dimensions that are not `[N]` or `[]`.
    MalformedArray(String),
    /// A length that is not a number (the length, the whole type).
    BadLength(String, String),
    /// More than 16 dimensions.
    TooManyDimensions(String),
}

impl std::fmt::Display for TypeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TypeError::MissingName(text) => write!(f, "missing type name in `{text}`"),
            TypeError::NotATypeName(name) => write!(f, "`{name}` is not a type name"),
            TypeError::MalformedArray(text) => write!(f, "malformed array type `{text}`"),
            TypeError::BadLength(n, text) => write!(f, "bad array length `{n}` in `{text}`"),
            TypeError::TooManyDimensions(text) => {
                write!(f, "too many array dimensions in `{text}`")
            }
        }
    }
}

impl std::error::Error for TypeError {}

impl TypeExpr {
    /// Parses `int32`, `float64[]`, `string[3][]`, `MyStruct`, ...
    ///
    /// Named types are accepted syntactically; whether they exist is checked
    /// against the [`TypeDefs`] when the model is compiled.
    pub fn parse(text: &str) -> Result<TypeExpr, TypeError> {
        let text = text.trim();
        let (base, dims) = match text.find('[') {
            Some(i) => (&text[..i], &text[i..]),
            None => (text, ""),
        };
        let base = base.trim();
        // The shared scalar names, the spec language's float names, then the spellings
        // only SCXML data declarations accept.
        let spec_float = matches!(
            Scalar::from_spec_name(base),
            Some(Scalar::F32 | Scalar::F64)
        );
        let mut ty = match (Scalar::from_name(base), base) {
            (Some(scalar), _) => TypeExpr::Base(scalar.into()),
            (None, _) if spec_float => TypeExpr::Base(BaseType::Float),
            (None, "integer") => TypeExpr::Base(BaseType::Int),
            (None, "URI" | "str") => TypeExpr::Base(BaseType::Str),
            (None, "") => return Err(TypeError::MissingName(text.to_owned())),
            (None, name) => {
                if name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '/' || c == ':')
                {
                    TypeExpr::Named(name.to_string())
                } else {
                    return Err(TypeError::NotATypeName(name.to_owned()));
                }
            }
        };
        // Dimensions, outermost first: `T[2][3]` is 2 arrays of 3.
        let mut sizes = Vec::new();
        let mut rest = dims.trim();
        while !rest.is_empty() {
            let Some(inner) = rest.strip_prefix('[') else {
                return Err(TypeError::MalformedArray(text.to_owned()));
            };
            let Some(close) = inner.find(']') else {
                return Err(TypeError::MalformedArray(text.to_owned()));
            };
            let n = inner[..close].trim();
            sizes.push(if n.is_empty() {
                None
            } else {
                Some(
                    n.parse::<u32>()
                        .map_err(|_| TypeError::BadLength(n.to_owned(), text.to_owned()))?,
                )
            });
            if sizes.len() > 16 {
                return Err(TypeError::TooManyDimensions(text.to_owned()));
            }
            rest = inner[close + 1..].trim_start();
        }
        for size in sizes.into_iter().rev() {
            ty = TypeExpr::Array(Box::new(ty), size);
        }
        Ok(ty)
    }
}

impl std::fmt::Display for TypeExpr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TypeExpr::Base(BaseType::Bool) => write!(f, "bool"),
            TypeExpr::Base(BaseType::Int) => write!(f, "int"),
            TypeExpr::Base(BaseType::Float) => write!(f, "float"),
            TypeExpr::Base(BaseType::Str) => write!(f, "string"),
            TypeExpr::Named(n) => write!(f, "{n}"),
            TypeExpr::Array(t, None) => write!(f, "{t}[]"),
            TypeExpr::Array(t, Some(n)) => write!(f, "{t}[{n}]"),
        }
    }
}

/// A type annotation and where it was written.
#[derive(Clone, Debug)]
pub struct TypeAnn {
    /// The type.
    pub ty: TypeExpr,
    /// Where the type was written.
    pub span: Span,
}

/// A type declared in `types.xml`.
#[derive(Clone, Debug)]
pub enum TypeDef {
    /// `<enumeration id>` with `<label id>`s: values are ints, labels are constants.
    Enumeration {
        /// Labels in declaration order.
        labels: Vec<String>,
    },
    /// `<struct id>` with `<field id type>`s, in declaration order.
    Struct {
        /// Field names and types, in declaration order.
        fields: Vec<(String, TypeExpr)>,
    },
}

/// The named types of a model, in declaration order.
#[derive(Clone, Debug, Default)]
pub struct TypeDefs {
    /// `(name, definition, where it was declared)`.
    pub defs: Vec<(String, TypeDef, Span)>,
}

impl TypeDefs {
    /// The definition of a named type.
    pub fn get(&self, name: &str) -> Option<&TypeDef> {
        self.defs
            .iter()
            .find(|(n, _, _)| n == name)
            .map(|(_, d, _)| d)
    }

    /// Reads a `<dataTypeList>` file already added to `sm`, appending its definitions.
    pub fn read(&mut self, sm: &SourceMap, file: FileId) -> Result<(), Vec<Diagnostic>> {
        let root = xml::parse(sm, file).map_err(|d| vec![d])?;
        let mut errs = Vec::new();
        if root.name != "dataTypeList" && root.name != "types" {
            return Err(vec![sm.diag(
                root.span,
                format!("expected <dataTypeList>, found <{}>", root.name),
            )]);
        }
        for node in &root.children {
            let el = match node {
                Node::Element(el) => el,
                Node::Text(span) => {
                    errs.push(sm.diag(*span, "unexpected text in <dataTypeList>"));
                    continue;
                }
                Node::Comment(..) => continue,
            };
            el.check_attrs(sm, &["id"], &mut errs);
            let id = match el.required(sm, "id") {
                Ok(a) => a.value.clone(),
                Err(d) => {
                    errs.push(d);
                    continue;
                }
            };
            if self.get(&id).is_some() {
                errs.push(sm.diag(el.span, format!("type `{id}` is declared twice")));
                continue;
            }
            match el.name.as_str() {
                "enumeration" => {
                    let mut labels = Vec::new();
                    for l in el.elements() {
                        if l.name != "label" {
                            errs.push(sm.diag(
                                l.span,
                                format!("unexpected <{}> in <enumeration>", l.name),
                            ));
                            continue;
                        }
                        l.check_attrs(sm, &["id"], &mut errs);
                        match l.required(sm, "id") {
                            Ok(a) if labels.contains(&a.value) => errs.push(sm.diag(
                                a.value_span,
                                format!("label `{}` is declared twice", a.value),
                            )),
                            Ok(a) => labels.push(a.value.clone()),
                            Err(d) => errs.push(d),
                        }
                    }
                    self.defs
                        .push((id, TypeDef::Enumeration { labels }, el.span));
                }
                "struct" | "structure" => {
                    let mut fields: Vec<(String, TypeExpr)> = Vec::new();
                    for fl in el.elements() {
                        if fl.name != "field" {
                            errs.push(
                                sm.diag(fl.span, format!("unexpected <{}> in <struct>", fl.name)),
                            );
                            continue;
                        }
                        fl.check_attrs(sm, &["id", "type"], &mut errs);
                        let (Ok(fid), Ok(fty)) = (fl.required(sm, "id"), fl.required(sm, "type"))
                        else {
                            errs.push(sm.diag(fl.span, "<field> needs `id` and `type`"));
                            continue;
                        };
                        if fields.iter().any(|(n, _)| *n == fid.value) {
                            errs.push(sm.diag(
                                fid.value_span,
                                format!("field `{}` is declared twice", fid.value),
                            ));
                            continue;
                        }
                        match TypeExpr::parse(&fty.value) {
                            Ok(t) => fields.push((fid.value.clone(), t)),
                            Err(m) => errs.push(sm.diag(fty.value_span, m.to_string())),
                        }
                    }
                    self.defs.push((id, TypeDef::Struct { fields }, el.span));
                }
                other => errs.push(sm.diag(
                    el.span,
                    format!("unexpected <{other}> in <dataTypeList> (expected <enumeration> or <struct>)"),
                )),
            }
        }
        if errs.is_empty() {
            Ok(())
        } else {
            Err(errs)
        }
    }
}

/// Parses a `TYPE name:type` comment body; `None` when the comment is not an annotation.
pub(crate) fn parse_type_comment(text: &str) -> Option<(String, Result<TypeExpr, TypeError>)> {
    let body = text.trim().strip_prefix("TYPE")?;
    if !body.starts_with(char::is_whitespace) {
        return None;
    }
    let body = body.trim();
    let (name, ty) = body.split_once(':')?;
    Some((name.trim().to_string(), TypeExpr::parse(ty)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_names_parse_to_their_base_type() {
        for s in Scalar::ALL {
            assert_eq!(TypeExpr::parse(s.name()), Ok(TypeExpr::Base(s.into())));
        }
        assert_eq!(TypeExpr::parse("int"), Ok(TypeExpr::Base(BaseType::Int)));
        assert_eq!(
            TypeExpr::parse("integer"),
            Ok(TypeExpr::Base(BaseType::Int))
        );
        assert_eq!(
            TypeExpr::parse("double"),
            Ok(TypeExpr::Base(BaseType::Float))
        );
    }

    #[test]
    fn type_expressions() {
        assert_eq!(TypeExpr::parse("int32"), Ok(TypeExpr::Base(BaseType::Int)));
        assert_eq!(
            TypeExpr::parse("float32[]"),
            Ok(TypeExpr::Array(
                Box::new(TypeExpr::Base(BaseType::Float)),
                None
            ))
        );
        assert_eq!(
            TypeExpr::parse("string[2][]").unwrap().to_string(),
            "string[][2]"
        );
        assert_eq!(
            TypeExpr::parse("int32[][][][]").unwrap().to_string(),
            "int[][][][]"
        );
        assert_eq!(
            TypeExpr::parse("int32[x]"),
            Err(TypeError::BadLength("x".into(), "int32[x]".into()))
        );
        assert_eq!(
            TypeExpr::parse("a b").unwrap_err().to_string(),
            "`a b` is not a type name"
        );
        assert!(TypeExpr::parse("int32[").is_err());
        assert!(TypeExpr::parse("").is_err());
        assert_eq!(TypeExpr::parse("Pose"), Ok(TypeExpr::Named("Pose".into())));
    }

    #[test]
    fn type_comments() {
        let (n, t) = parse_type_comment(" TYPE percentage:int32 ").unwrap();
        assert_eq!(n, "percentage");
        assert_eq!(t, Ok(TypeExpr::Base(BaseType::Int)));
        assert!(parse_type_comment(" just a comment ").is_none());
        assert!(parse_type_comment("TYPES x:int").is_none());
    }

    #[test]
    fn types_xml() {
        let mut sm = SourceMap::new();
        let f = sm.add(
            "types.xml",
            r#"<dataTypeList>
                 <enumeration id="Color"><label id="RED"/><label id="GREEN"/></enumeration>
                 <struct id="Point"><field id="x" type="float64"/><field id="y" type="int32[]"/></struct>
               </dataTypeList>"#
                .to_string(),
        );
        let mut defs = TypeDefs::default();
        defs.read(&sm, f).unwrap();
        assert!(
            matches!(defs.get("Color"), Some(TypeDef::Enumeration { labels }) if labels.len() == 2)
        );
        assert!(
            matches!(defs.get("Point"), Some(TypeDef::Struct { fields }) if fields[1].0 == "y")
        );
        let g = sm.add(
            "bad.xml",
            "<dataTypeList><struct id='S'><field id='x'/></struct></dataTypeList>".into(),
        );
        assert!(defs.read(&sm, g).is_err());
    }
}
