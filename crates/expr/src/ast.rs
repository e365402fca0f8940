//! Syntax tree of the ECMAScript subset; every node keeps its byte range in the expression text.

/// Unary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    /// `-x`
    Neg,
    /// `+x`
    Plus,
    /// `!x`
    Not,
    /// `~x` (bitwise complement of an integer)
    BitNot,
}

/// Binary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/` (always a float result, as in ECMAScript)
    Div,
    /// `%`
    Rem,
    /// `==` / `===`
    Eq,
    /// `!=` / `!==`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `&&`
    And,
    /// `||`
    Or,
    /// `&` (bitwise, on integers)
    BitAnd,
    /// `|` (bitwise, on integers)
    BitOr,
    /// `^` (bitwise exclusive or, on integers)
    BitXor,
}

impl BinOp {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::And => "&&",
            BinOp::Or => "||",
            BinOp::BitAnd => "&",
            BinOp::BitOr => "|",
            BinOp::BitXor => "^",
        }
    }
}

/// An expression node and its byte range `[start, end)` in the source text.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What the node is.
    pub kind: ExprKind,
    /// Byte offset of the first character.
    pub start: u32,
    /// Byte offset just past the last character.
    pub end: u32,
}

/// The kinds of expression node.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// Integer literal.
    Int(i64),
    /// Number literal with a fraction or exponent.
    Float(f64),
    /// `true` / `false`.
    Bool(bool),
    /// String literal (quotes removed, escapes resolved).
    Str(String),
    /// `[a, b, ...]`.
    Array(Vec<Expr>),
    /// `{a: x, 'b': y}`: an object literal, typed by the declared struct it is stored in.
    Object(Vec<ObjField>),
    /// A name: a variable, an enumeration label, `_event` or `Math`.
    Ident(String),
    /// `object.field`; the `u32` is the field name's offset.
    Member(Box<Expr>, String, u32),
    /// `array[index]`.
    Index(Box<Expr>, Box<Expr>),
    /// `callee(args)`.
    Call(Box<Expr>, Vec<Expr>),
    /// Unary operation.
    Unary(UnOp, Box<Expr>),
    /// Binary operation.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `c ? a : b`.
    Cond(Box<Expr>, Box<Expr>, Box<Expr>),
}

/// One `key: value` entry of an object literal.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjField {
    /// The key (quotes removed).
    pub name: String,
    /// Byte offset of the key.
    pub at: u32,
    /// The value.
    pub value: Expr,
}
