//! How a parameter of [`crate::params::ScaledParams`] is declared, read and checked: the
//! declaring macros (`param_group!` for a group of fields, `param_groups!` for the struct
//! of groups, `param_enum!` for an enum parameter), the types a parameter can have
//! ([`Kind`]: a number, a whole number, a switch, one of an enum's names, a name), the
//! ranges it can be declared with ([`Rule`]: a [`Bound`], a [`NameRule`], [`Any`]), and
//! the one setter every key goes through, which reads the value as the field's type,
//! checks it against the declared range and assigns that field (nothing is serialized).
//! The table by key ([`crate::param_table`]) is built from what the macros generate.

use std::fmt;

/// A parameter's value, typed: what
/// [`ScaledParams::get`](crate::params::ScaledParams::get) returns and
/// [`ScaledParams::set`](crate::params::ScaledParams::set) takes. Displayed as `--set`
/// would spell it (`0.5`, `3`, `true`, `closed-form`, `inf`).
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// A switch.
    Bool(bool),
    /// A whole number (a count; as a value it may set a number too).
    Int(i64),
    /// A number (`inf` where the range allows it).
    Number(f64),
    /// An enum's name, a factor's name, or text to be read as the field's type.
    Name(String),
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::Int(i) => write!(f, "{i}"),
            // `{:?}` keeps a number's kind visible (`1.0`, not `1`) and writes `inf`.
            ParamValue::Number(x) => write!(f, "{x:?}"),
            ParamValue::Name(s) => f.write_str(s),
        }
    }
}

/// The type of a parameter, as the table reads values for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValueKind {
    /// A number (`f64`).
    Number,
    /// A whole number (a count).
    Whole,
    /// `true` or `false`.
    Switch,
    /// One of an enum's names (canonical names, in declaration order).
    OneOf(&'static [&'static str]),
    /// Free text checked by the field's [`NameRule`].
    Text,
}

/// One parameter of the table: the group it belongs to (a field of
/// [`ScaledParams`](crate::params::ScaledParams)), its key (the group's field, as
/// serialized), its type and its declared range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Key {
    /// The group, e.g. `gate`.
    pub group: String,
    /// The key, e.g. `epsilon`.
    pub name: String,
    /// How values are read for it.
    pub kind: ValueKind,
    /// The range of a number or a count.
    pub bound: Option<Bound>,
    /// The declared range in words (a [`Bound`]'s or a [`Names`] rule's), if any.
    pub range: Option<&'static str>,
}

impl Key {
    /// `group.key`, e.g. `gate.epsilon`.
    pub fn dotted(&self) -> String {
        format!("{}.{}", self.group, self.name)
    }
}

/// Why a value does not fit a field: the setter turns it into the message of
/// [`crate::error::SetError::BadValue`] with the field's declared range.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// The value is not of the field's type, e.g. `"a number"`.
    NotA(&'static str),
    /// The value is of the type but outside the declared range.
    OutOfRange,
    /// What the value must be, e.g. `"true or false"`, `"one of: a, b"`.
    Must(String),
}

/// A type a parameter can have: how text and typed values are read as it, and its value.
pub trait Kind: Sized {
    /// How the table reads values of this type.
    const KIND: ValueKind;
    /// Reads `--set` text.
    fn from_text(text: &str) -> Result<Self, Refusal>;
    /// Reads a typed value.
    fn from_value(value: &ParamValue) -> Result<Self, Refusal>;
    /// The value, typed.
    fn value(&self) -> ParamValue;
}

impl Kind for f64 {
    const KIND: ValueKind = ValueKind::Number;
    fn from_text(text: &str) -> Result<Self, Refusal> {
        text.parse().map_err(|_| Refusal::NotA("a number"))
    }
    fn from_value(value: &ParamValue) -> Result<Self, Refusal> {
        match value {
            ParamValue::Number(x) => Ok(*x),
            ParamValue::Int(i) => Ok(*i as f64),
            ParamValue::Name(s) => Self::from_text(s),
            ParamValue::Bool(_) => Err(Refusal::NotA("a number")),
        }
    }
    fn value(&self) -> ParamValue {
        ParamValue::Number(*self)
    }
}

/// Counts: read as a whole number, refused as out of range where the type cannot hold it.
macro_rules! whole_kind {
    ($($t:ty),*) => {$(
        impl Kind for $t {
            const KIND: ValueKind = ValueKind::Whole;
            fn from_text(text: &str) -> Result<Self, Refusal> {
                let x: u64 = text.parse().map_err(|_| Refusal::NotA("a whole number"))?;
                <$t>::try_from(x).map_err(|_| Refusal::OutOfRange)
            }
            fn from_value(value: &ParamValue) -> Result<Self, Refusal> {
                match value {
                    ParamValue::Int(i) => <$t>::try_from(*i).map_err(|_| Refusal::OutOfRange),
                    ParamValue::Name(s) => Self::from_text(s),
                    _ => Err(Refusal::NotA("a whole number")),
                }
            }
            fn value(&self) -> ParamValue {
                ParamValue::Int(i64::try_from(*self).unwrap_or(i64::MAX))
            }
        }
    )*};
}
whole_kind!(usize, u32);

impl Kind for bool {
    const KIND: ValueKind = ValueKind::Switch;
    fn from_text(text: &str) -> Result<Self, Refusal> {
        match text.to_ascii_lowercase().as_str() {
            "true" | "yes" | "1" => Ok(true),
            "false" | "no" | "0" => Ok(false),
            _ => Err(Refusal::Must("true or false".into())),
        }
    }
    fn from_value(value: &ParamValue) -> Result<Self, Refusal> {
        match value {
            ParamValue::Bool(b) => Ok(*b),
            ParamValue::Name(s) => Self::from_text(s),
            _ => Err(Refusal::Must("true or false".into())),
        }
    }
    fn value(&self) -> ParamValue {
        ParamValue::Bool(*self)
    }
}

impl Kind for String {
    const KIND: ValueKind = ValueKind::Text;
    fn from_text(text: &str) -> Result<Self, Refusal> {
        Ok(text.to_string())
    }
    fn from_value(value: &ParamValue) -> Result<Self, Refusal> {
        Ok(value.to_string())
    }
    fn value(&self) -> ParamValue {
        ParamValue::Name(self.clone())
    }
}

/// An enum parameter's names: `(name, variant)` for every canonical name and alias, as
/// declared with `param_enum!` (which also gives serde the same names).
pub trait Names: Sized + Copy + 'static {
    /// The canonical names, in declaration order.
    const CANONICAL: &'static [&'static str];
    /// Every name (canonical and alias) with its variant.
    fn named() -> &'static [(&'static str, Self)];
    /// The canonical name of a variant.
    fn name(self) -> &'static str;
}

/// The range a field's values must lie in, as declared with it: a [`Bound`] for numbers
/// and counts, a [`NameRule`] for names, [`Any`] for switches and enums.
pub trait Rule<T> {
    /// The value as stored (e.g. `none` as the empty list).
    fn normal(&self, x: T) -> T {
        x
    }
    /// Whether the stored value `x` is in range.
    fn allows(&self, x: &T) -> bool;
    /// The range in words, as errors state it.
    fn range(&self) -> Option<&'static str>;
    /// The [`Bound`], for numbers and counts.
    fn bound(&self) -> Option<Bound> {
        None
    }
}

/// No range: every value of the type is allowed (switches, enums).
#[derive(Debug, Clone, Copy)]
pub struct Any;

impl<T> Rule<T> for Any {
    fn allows(&self, _: &T) -> bool {
        true
    }
    fn range(&self) -> Option<&'static str> {
        None
    }
}

impl Rule<f64> for Bound {
    fn allows(&self, x: &f64) -> bool {
        self.admits(*x)
    }
    fn range(&self) -> Option<&'static str> {
        Some(self.expected())
    }
    fn bound(&self) -> Option<Bound> {
        Some(*self)
    }
}

macro_rules! whole_rule {
    ($($t:ty),*) => {$(
        impl Rule<$t> for Bound {
            fn allows(&self, x: &$t) -> bool {
                self.admits(*x as f64)
            }
            fn range(&self) -> Option<&'static str> {
                Some(self.expected())
            }
            fn bound(&self) -> Option<Bound> {
                Some(*self)
            }
        }
    )*};
}
whole_rule!(usize, u32);

/// The spelling of factor names (whether they name factors of a model is checked where a
/// model is known, [`crate::params::CheckedScaledParams::check_factors`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NameRule {
    /// A factor's name: not empty, no spaces, no `+`.
    Factor,
    /// Factor names joined by `+` (no spaces, none twice), or `""` (also written `none`).
    FactorList,
}

/// Not a factor's name: empty, with a space or with a `+`.
fn bad_name(n: &str) -> bool {
    n.is_empty() || n.contains('+') || n.chars().any(char::is_whitespace)
}

impl Rule<String> for NameRule {
    fn normal(&self, x: String) -> String {
        match self {
            NameRule::FactorList if x.trim() == "none" => String::new(),
            _ => x,
        }
    }
    fn allows(&self, x: &String) -> bool {
        match self {
            NameRule::Factor => !bad_name(x),
            NameRule::FactorList => {
                let names: Vec<&str> = x.split('+').collect();
                let twice = names.iter().enumerate().any(|(i, n)| names[..i].contains(n));
                x.is_empty() || !(twice || names.iter().any(|n| bad_name(n)))
            }
        }
    }
    fn range(&self) -> Option<&'static str> {
        Some(match self {
            NameRule::Factor => "a factor's name (not empty, no spaces, no `+`)",
            NameRule::FactorList => {
                "factor names joined by `+` (no spaces, none twice, not gate_factor), or \"\" / none"
            }
        })
    }
}

/// A value to set, as given: `--set` text or a typed value.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Given<'a> {
    Text(&'a str),
    Value(&'a ParamValue),
}

/// Sets `field` to the value `given`, read as `T` and checked against `rule`: the one
/// setter every key of the table goes through. On error `field` is unchanged and the
/// error states what the value must be.
pub(crate) fn set_field<T: Kind, R: Rule<T>>(field: &mut T, rule: &R, given: Given<'_>) -> Result<(), String> {
    let read = match given {
        Given::Text(t) => T::from_text(t),
        Given::Value(v) => T::from_value(v),
    };
    let x = read.map(|x| rule.normal(x)).and_then(|x| {
        if rule.allows(&x) {
            Ok(x)
        } else {
            Err(Refusal::OutOfRange)
        }
    });
    let range = rule.range().unwrap_or("");
    match x {
        Ok(x) => {
            *field = x;
            Ok(())
        }
        Err(Refusal::NotA(what)) => {
            let shown = match given {
                Given::Text(t) => t.to_string(),
                Given::Value(v) => v.to_string(),
            };
            Err(format!("'{shown}' is not {what}; must be {range}"))
        }
        Err(Refusal::OutOfRange) => Err(format!("must be {range}")),
        Err(Refusal::Must(what)) => Err(format!("must be {what}")),
    }
}

/// The [`crate::error::ParamError`] of `field` if it is out of `rule`'s range.
pub(crate) fn field_problem<T: Kind, R: Rule<T>>(
    key: &'static str,
    field: &T,
    rule: &R,
) -> Option<crate::error::ParamError> {
    if rule.allows(field) {
        return None;
    }
    let shown = match field.value() {
        ParamValue::Number(x) => x.to_string(),
        ParamValue::Name(s) => format!("{s:?}"),
        other => other.to_string(),
    };
    Some(crate::error::ParamError::new(key, shown, rule.range().unwrap_or("")))
}

/// The table entry of a declared field (used by `param_group!`).
pub(crate) fn entry<T: Kind, R: Rule<T>>(group: &str, key: &str, rule: &R) -> Key {
    Key {
        group: group.to_string(),
        name: key.to_string(),
        kind: T::KIND,
        bound: rule.bound(),
        range: rule.range(),
    }
}

/// A field's rule: the declared one, or [`Any`] where none is declared.
macro_rules! rule_or_any {
    () => {
        $crate::param_decl::Any
    };
    ($rule:expr) => {
        $rule
    };
}
pub(crate) use rule_or_any;

/// Declares one group of [`ScaledParams`](crate::params::ScaledParams): the struct (its
/// serde names are the keys, every field defaulted), its `Default`, and its part of the
/// table: the entries, the typed getter and setter by key, and the range checks. Each field is
/// `name: Type = default => "key"`, optionally followed by `in RULE` (a [`Rule`] of the
/// type: a [`Bound`], a [`NameRule`]); other attributes (docs, serde `with`) pass through.
macro_rules! param_group {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $(
                $(#[$fmeta:meta])*
                $field:ident : $ty:ty = $default:expr => $key:literal $(in $rule:expr)?
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $(
                $(#[$fmeta])*
                #[serde(rename = $key)]
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self { $( $field: $default, )* }
            }
        }

        impl $name {
            /// The group's entries of the table (the group named `group`), in declaration order.
            pub(crate) fn entries(group: &str) -> Vec<$crate::param_decl::Key> {
                vec![$(
                    $crate::param_decl::entry::<$ty, _>(
                        group,
                        $key,
                        &$crate::param_decl::rule_or_any!($($rule)?),
                    ),
                )*]
            }

            /// The value of the field `key`, if the group has it.
            pub(crate) fn get(&self, key: &str) -> Option<$crate::param_decl::ParamValue> {
                match key {
                    $( $key => Some($crate::param_decl::Kind::value(&self.$field)), )*
                    _ => None,
                }
            }

            /// Sets the field `key` (if the group has it) to the value given.
            pub(crate) fn set(
                &mut self,
                key: &str,
                given: $crate::param_decl::Given<'_>,
            ) -> Option<Result<(), String>> {
                match key {
                    $( $key => Some($crate::param_decl::set_field(
                        &mut self.$field,
                        &$crate::param_decl::rule_or_any!($($rule)?),
                        given,
                    )), )*
                    _ => None,
                }
            }

            /// Every field out of its declared range, in declaration order.
            pub(crate) fn problems(&self, out: &mut Vec<$crate::error::ParamError>) {
                $(
                    out.extend($crate::param_decl::field_problem(
                        $key,
                        &self.$field,
                        &$crate::param_decl::rule_or_any!($($rule)?),
                    ));
                )*
            }
        }
    };
}
pub(crate) use param_group;

/// Declares [`ScaledParams`](crate::params::ScaledParams), a struct of groups declared
/// with `param_group!` (each field's name is the group's key), and its table: the entries
/// of every group, and the getter, the setter and the range checks by group and key.
macro_rules! param_groups {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $(
                $(#[$fmeta:meta])*
                $field:ident : $ty:ty
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $(
                $(#[$fmeta])*
                pub $field: $ty,
            )*
        }

        impl $name {
            /// Every entry of the table, group by group in declaration order.
            pub(crate) fn entries() -> Vec<$crate::param_decl::Key> {
                let mut all = Vec::new();
                $( all.extend(<$ty>::entries(stringify!($field))); )*
                all
            }

            /// The value of `group.key`, if there is such a field.
            pub(crate) fn group_get(&self, group: &str, key: &str) -> Option<$crate::param_decl::ParamValue> {
                match group {
                    $( stringify!($field) => self.$field.get(key), )*
                    _ => None,
                }
            }

            /// Sets `group.key` (if there is such a field) to the value given.
            pub(crate) fn group_set(
                &mut self,
                group: &str,
                key: &str,
                given: $crate::param_decl::Given<'_>,
            ) -> Option<Result<(), String>> {
                match group {
                    $( stringify!($field) => self.$field.set(key, given), )*
                    _ => None,
                }
            }

            /// Every field out of its declared range, group by group in declaration order.
            pub(crate) fn field_problems(&self) -> Vec<$crate::error::ParamError> {
                let mut out = Vec::new();
                $( self.$field.problems(&mut out); )*
                out
            }
        }
    };
}
pub(crate) use param_groups;

/// Declares an enum parameter: the enum (serde reads and writes the declared names, and
/// reads the aliases after `|`), its `Default` (`#[default]`), and its [`Names`] and
/// [`Kind`], so the table reads the same names and lists the canonical ones in errors.
macro_rules! param_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $(
                $(#[$vmeta:meta])*
                $variant:ident = $canonical:literal $(| $alias:literal)*
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
        pub enum $name {
            $(
                $(#[$vmeta])*
                #[serde(rename = $canonical $(, alias = $alias)*)]
                $variant,
            )*
        }

        impl $crate::param_decl::Names for $name {
            const CANONICAL: &'static [&'static str] = &[$($canonical),*];
            fn named() -> &'static [(&'static str, Self)] {
                &[$( ($canonical, $name::$variant), $( ($alias, $name::$variant), )* )*]
            }
            fn name(self) -> &'static str {
                match self {
                    $( $name::$variant => $canonical, )*
                }
            }
        }

        impl $crate::param_decl::Kind for $name {
            const KIND: $crate::param_decl::ValueKind =
                $crate::param_decl::ValueKind::OneOf(<$name as $crate::param_decl::Names>::CANONICAL);
            fn from_text(text: &str) -> Result<Self, $crate::param_decl::Refusal> {
                $crate::param_decl::named(text)
            }
            fn from_value(value: &$crate::param_decl::ParamValue) -> Result<Self, $crate::param_decl::Refusal> {
                $crate::param_decl::named(&value.to_string())
            }
            fn value(&self) -> $crate::param_decl::ParamValue {
                $crate::param_decl::ParamValue::Name(
                    $crate::param_decl::Names::name(*self).to_string(),
                )
            }
        }
    };
}
pub(crate) use param_enum;

/// The variant of an enum named `text` (a canonical name or an alias).
pub fn named<E: Names>(text: &str) -> Result<E, Refusal> {
    E::named()
        .iter()
        .find(|(n, _)| *n == text)
        .map(|(_, v)| *v)
        .ok_or_else(|| Refusal::Must(format!("one of: {}", E::CANONICAL.join(", "))))
}

/// The range of a number or a count, as the range checks enforce it and error messages
/// state it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// Finite and > 0.
    Positive,
    /// Finite and >= 0.
    NonNegative,
    /// In (0, 1].
    HalfOpenUnit,
    /// In [0, 1).
    BelowOne,
    /// > 0, infinity allowed.
    PositiveOrInf,
    /// A whole number in `1..=max`: counts that size an allocation or a loop, so that no
    /// setting asks for more memory or time than a run has.
    Count {
        /// Largest value.
        max: usize,
        /// The range and why, e.g. `"in 1..=1000 (...)"`.
        expected: &'static str,
    },
}

impl Bound {
    /// The range in words, as error messages give it.
    pub fn expected(self) -> &'static str {
        match self {
            Bound::Positive => "finite and > 0",
            Bound::NonNegative => "finite and >= 0",
            Bound::HalfOpenUnit => "in (0, 1]",
            Bound::BelowOne => "in [0, 1)",
            Bound::PositiveOrInf => "> 0 (inf for unbounded)",
            Bound::Count { expected, .. } => expected,
        }
    }

    /// Whether `x` is in range (a count must be whole).
    pub fn admits(self, x: f64) -> bool {
        match self {
            Bound::Positive => x > 0.0 && x.is_finite(),
            Bound::NonNegative => x >= 0.0 && x.is_finite(),
            Bound::HalfOpenUnit => x > 0.0 && x <= 1.0,
            Bound::BelowOne => (0.0..1.0).contains(&x),
            Bound::PositiveOrInf => x > 0.0,
            Bound::Count { max, .. } => x.fract() == 0.0 && x >= 1.0 && x <= max as f64,
        }
    }
}
