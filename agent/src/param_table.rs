//! The scaled agent's parameters by name: one table, generated with the parameter groups
//! of [`ScaledParams`] from their one declaration (the `param_group!` and `param_enum!`
//! macros of this module, used in [`crate::params`]). Each field is declared once with its
//! key, its type and its range; the struct, its serde names, its setter by key, its
//! getter and the range checks of [`ScaledParams::check`] all come from that line, so a
//! field added to a group is listed, read, set and checked by name with no other edit.
//!
//! A key is a field's serialized name (`epsilon`, `horizon`, `scaling_mode`), or
//! `group.key` (`gate.epsilon`), or an alias of [`ALIASES`]. Two entry points set a
//! parameter: [`ScaledParams::set_str`] takes the text of `--set key=value`,
//! [`ScaledParams::set`] a typed [`ParamValue`] (keyword arguments of other front ends).
//! Both find the field by key, read the value as the field's type ([`Kind`]: a number, a
//! whole number, a switch, one of an enum's names, a name), check it against the field's
//! declared range ([`Rule`]: a [`Bound`] or a [`Names`] rule) and assign that one field;
//! nothing is serialized. An unknown key or a bad value is a [`SetError`] naming the key,
//! the value and what is allowed (the declared range or the enum's names), and leaves the
//! parameters unchanged.
//!
//! ```
//! use unforeseen_agent::param_table::ParamValue;
//! use unforeseen_agent::params::{ScaledParams, ScalingMode};
//! let mut p = ScaledParams::default();
//! p.set_str("scaling_mode", "closed-form").unwrap();
//! p.set("gate.epsilon", ParamValue::Number(0.1)).unwrap();
//! assert_eq!(p.scaling.scaling_mode, ScalingMode::ClosedForm);
//! assert_eq!(p.get("epsilon").unwrap(), ParamValue::Number(0.1));
//! assert!(p.set_str("horizon", "9").unwrap_err().to_string().contains("1..=8"));
//! ```

use std::fmt;
use std::sync::OnceLock;

use crate::error::SetError;
use crate::params::{Bound, ScaledParams};

/// A parameter's value, typed: what [`ScaledParams::get`] returns and
/// [`ScaledParams::set`] takes. Displayed as `--set` would spell it (`0.5`, `3`, `true`,
/// `closed-form`, `inf`).
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
    /// Free text checked by the field's [`Names`] rule.
    Text,
}

/// One parameter of the table: the group it belongs to (a field of [`ScaledParams`]), its
/// key (the group's field, as serialized), its type and its declared range.
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

/// Keys accepted besides the table's: `(alias, key)`. `sample=true|false` is
/// `action_selection=sample|outcome-mode` (the default mode).
pub const ALIASES: &[(&str, &str)] = &[("sample", "action_selection")];

/// Why a value does not fit a field: the setter turns it into the message of
/// [`SetError::BadValue`] with the field's declared range.
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
pub(crate) fn bad_name(n: &str) -> bool {
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
        $crate::param_table::Any
    };
    ($rule:expr) => {
        $rule
    };
}
pub(crate) use rule_or_any;

/// Declares one group of [`ScaledParams`]: the struct (its serde names are the keys,
/// every field defaulted), its `Default`, and its part of the table: the entries, the
/// typed getter and setter by key, and the range checks. Each field is
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
            pub(crate) fn entries(group: &str) -> Vec<$crate::param_table::Key> {
                vec![$(
                    $crate::param_table::entry::<$ty, _>(
                        group,
                        $key,
                        &$crate::param_table::rule_or_any!($($rule)?),
                    ),
                )*]
            }

            /// The value of the field `key`, if the group has it.
            pub(crate) fn get(&self, key: &str) -> Option<$crate::param_table::ParamValue> {
                match key {
                    $( $key => Some($crate::param_table::Kind::value(&self.$field)), )*
                    _ => None,
                }
            }

            /// Sets the field `key` (if the group has it) to the value given.
            pub(crate) fn set(
                &mut self,
                key: &str,
                given: $crate::param_table::Given<'_>,
            ) -> Option<Result<(), String>> {
                match key {
                    $( $key => Some($crate::param_table::set_field(
                        &mut self.$field,
                        &$crate::param_table::rule_or_any!($($rule)?),
                        given,
                    )), )*
                    _ => None,
                }
            }

            /// Every field out of its declared range, in declaration order.
            pub(crate) fn problems(&self, out: &mut Vec<$crate::error::ParamError>) {
                $(
                    out.extend($crate::param_table::field_problem(
                        $key,
                        &self.$field,
                        &$crate::param_table::rule_or_any!($($rule)?),
                    ));
                )*
            }
        }
    };
}
pub(crate) use param_group;

/// Declares [`ScaledParams`], a struct of groups declared with `param_group!` (each
/// field's name is the group's key), and its table: the entries of every group, and the
/// getter, the setter and the range checks by group and key.
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
            pub(crate) fn entries() -> Vec<$crate::param_table::Key> {
                let mut all = Vec::new();
                $( all.extend(<$ty>::entries(stringify!($field))); )*
                all
            }

            /// The value of `group.key`, if there is such a field.
            pub(crate) fn group_get(&self, group: &str, key: &str) -> Option<$crate::param_table::ParamValue> {
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
                given: $crate::param_table::Given<'_>,
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

        impl $crate::param_table::Names for $name {
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

        impl $crate::param_table::Kind for $name {
            const KIND: $crate::param_table::ValueKind =
                $crate::param_table::ValueKind::OneOf(<$name as $crate::param_table::Names>::CANONICAL);
            fn from_text(text: &str) -> Result<Self, $crate::param_table::Refusal> {
                $crate::param_table::named(text)
            }
            fn from_value(value: &$crate::param_table::ParamValue) -> Result<Self, $crate::param_table::Refusal> {
                $crate::param_table::named(&value.to_string())
            }
            fn value(&self) -> $crate::param_table::ParamValue {
                $crate::param_table::ParamValue::Name(
                    $crate::param_table::Names::name(*self).to_string(),
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

/// Every parameter, sorted by group, then by key.
pub fn keys() -> &'static [Key] {
    static KEYS: OnceLock<Vec<Key>> = OnceLock::new();
    KEYS.get_or_init(|| {
        let mut all = ScaledParams::entries();
        all.sort_by(|a, b| (&a.group, &a.name).cmp(&(&b.group, &b.name)));
        all
    })
}

/// Every key (flat), in the order of [`keys`]: what `--set` and error messages list.
pub fn key_names() -> Vec<&'static str> {
    keys().iter().map(|k| k.name.as_str()).collect()
}

/// The parameter `key` names (flat, dotted or an alias).
pub fn lookup(key: &str) -> Result<&'static Key, SetError> {
    let k = key.trim();
    let k = ALIASES.iter().find(|(a, _)| *a == k).map_or(k, |(_, to)| *to);
    let found = match k.split_once('.') {
        Some((g, n)) => keys().iter().find(|x| x.group == g && x.name == n),
        None => keys().iter().find(|x| x.name == k),
    };
    found.ok_or_else(|| SetError::UnknownKey {
        key: key.to_string(),
        known: key_names(),
    })
}

impl ScaledParams {
    /// The value of the parameter `key` (enums by their kebab-case names).
    pub fn get(&self, key: &str) -> Result<ParamValue, SetError> {
        let k = lookup(key)?;
        self.group_get(&k.group, &k.name).ok_or_else(|| SetError::UnknownKey {
            key: key.to_string(),
            known: key_names(),
        })
    }

    /// Sets the parameter `key` to a typed value: a number or a whole number for a number,
    /// a whole number for a count, a bool for a switch, a name for an enum or a factor
    /// name (and text is read as `--set` reads it). Checks the field's declared range. On
    /// error the parameters are unchanged.
    pub fn set(&mut self, key: &str, value: ParamValue) -> Result<(), SetError> {
        self.set_given(key, Given::Value(&value), || value.to_string())
    }

    /// Sets the parameter `key` from text (`--set key=value`): a number, a whole number,
    /// `true`/`false` (also `yes`/`no`, `1`/`0`) or a name, as the field's type calls for;
    /// `inf` where a range allows it. Checks the field's declared range. On error the
    /// parameters are unchanged.
    pub fn set_str(&mut self, key: &str, text: &str) -> Result<(), SetError> {
        let text = text.trim();
        self.set_given(key, Given::Text(text), || text.to_string())
    }

    fn set_given(&mut self, key: &str, given: Given<'_>, shown: impl Fn() -> String) -> Result<(), SetError> {
        let k = lookup(key)?;
        let result = self
            .group_set(&k.group, &k.name, given)
            .ok_or_else(|| SetError::UnknownKey {
                key: key.to_string(),
                known: key_names(),
            })?;
        result.map_err(|problem| SetError::BadValue {
            key: key.to_string(),
            value: shown(),
            problem,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{GateMode, ScalingMode};
    use proptest::strategy::BoxedStrategy;

    /// A value of each key other than its default, as `--set` text and typed.
    fn other_value(p: &ScaledParams, key: &str) -> (String, ParamValue) {
        let k = lookup(key).unwrap();
        match (p.get(key).unwrap(), k.kind) {
            (ParamValue::Bool(b), _) => ((!b).to_string(), ParamValue::Bool(!b)),
            (ParamValue::Int(n), _) => {
                let x = if n == 1 { 2 } else { 1 };
                (x.to_string(), ParamValue::Int(x))
            }
            (ParamValue::Number(x), _) => {
                let x = x * 0.5;
                (x.to_string(), ParamValue::Number(x))
            }
            // Not `d` or `L`: those are pooled over by default.
            (ParamValue::Name(s), _) if key == "gate_factor" => {
                let x = if s == "v" { "p" } else { "v" };
                (x.to_string(), ParamValue::Name(x.into()))
            }
            (ParamValue::Name(_), _) if key == "persistence_ignores" => ("d".into(), ParamValue::Name("d".into())),
            (ParamValue::Name(s), ValueKind::OneOf(names)) => {
                let x = names.iter().find(|v| **v != s).unwrap().to_string();
                (x.clone(), ParamValue::Name(x))
            }
            (other, kind) => panic!("{key}: unexpected {other} of {kind:?}"),
        }
    }

    #[test]
    fn keys_are_unique_and_every_number_has_a_range() {
        let names = key_names();
        for (i, k) in names.iter().enumerate() {
            assert!(!names[..i].contains(k), "key {k} twice");
        }
        assert_eq!(names.len(), 35);
        for k in keys() {
            if matches!(k.kind, ValueKind::Number | ValueKind::Whole) {
                assert!(k.bound.is_some(), "{} has no range", k.name);
            }
        }
    }

    #[test]
    fn every_key_round_trips_as_text_and_typed() {
        for k in keys() {
            let base = ScaledParams::default();
            let (text, value) = other_value(&base, &k.name);
            let mut by_text = base.clone();
            by_text.set_str(&k.name, &text).unwrap();
            assert_ne!(by_text, base, "{} did not change", k.name);
            assert_eq!(by_text.get(&k.name).unwrap(), value, "{}", k.name);
            let mut typed = base.clone();
            typed.set(&k.dotted(), value.clone()).unwrap();
            assert_eq!(typed, by_text, "{}: typed and text differ", k.name);
            by_text.check_ref().unwrap();
        }
    }

    #[test]
    fn unknown_keys_and_bad_values_name_key_and_allowed_values() {
        let mut p = ScaledParams::default();
        let e = p.set_str("colour", "red").unwrap_err().to_string();
        assert!(
            e.contains("colour") && e.contains("omega") && e.contains("scaling_mode"),
            "{e}"
        );
        let e = p.set_str("scaling_mode", "closed").unwrap_err().to_string();
        assert!(
            e.contains("scaling_mode") && e.contains("iterative, closed-form"),
            "{e}"
        );
        let e = p.set_str("horizon", "9").unwrap_err().to_string();
        assert!(
            e.contains("horizon") && e.contains("1..=8") && e.contains("policies"),
            "{e}"
        );
        let e = p.set_str("horizon", "two").unwrap_err().to_string();
        assert!(
            e.contains("horizon") && e.contains("whole number") && e.contains("1..=8"),
            "{e}"
        );
        let e = p.set_str("omega", "inf").unwrap_err().to_string();
        assert!(e.contains("omega") && e.contains("finite and > 0"), "{e}");
        let e = p.set("gamma", ParamValue::Name("big".into())).unwrap_err().to_string();
        assert!(
            e.contains("gamma") && e.contains("big") && e.contains("finite and > 0"),
            "{e}"
        );
        let e = p.set_str("learning", "maybe").unwrap_err().to_string();
        assert!(e.contains("learning") && e.contains("true or false"), "{e}");
        let e = p.set_str("gate_factor", "a b").unwrap_err().to_string();
        assert!(e.contains("gate_factor") && e.contains("no spaces"), "{e}");
        let e = p.set_str("max_scaling_iters", "4294967297").unwrap_err().to_string();
        assert!(e.contains("max_scaling_iters") && e.contains("1..=10000"), "{e}");
        let e = p.set("horizon", ParamValue::Int(-1)).unwrap_err().to_string();
        assert!(e.contains("horizon") && e.contains("-1") && e.contains("1..=8"), "{e}");
        assert_eq!(p, ScaledParams::default(), "a failed set changes nothing");
    }

    #[test]
    fn spellings_of_earlier_versions_are_accepted() {
        let mut p = ScaledParams::default();
        p.set_str("sample", "true").unwrap();
        assert_eq!(p.get("action_selection").unwrap(), ParamValue::Name("sample".into()));
        p.set_str("sample", "no").unwrap();
        assert_eq!(
            p.get("action_selection").unwrap(),
            ParamValue::Name("outcome-mode".into())
        );
        p.set("sample", ParamValue::Bool(true)).unwrap();
        assert_eq!(p.get("action_selection").unwrap(), ParamValue::Name("sample".into()));
        p.set_str("gate", "one-step").unwrap();
        assert_eq!(p.gate.mode, GateMode::OneStep);
        p.set_str("persistence_ignores", "none").unwrap();
        assert_eq!(p.planning.persistence_ignores, "");
        p.set_str("gate_memory", "inf").unwrap();
        assert_eq!(p.gate.gate_memory, f64::INFINITY);
        p.set_str("omega", "0.3").unwrap();
        assert_eq!(p.gate.gate_memory, f64::INFINITY, "inf survives setting another key");
        p.set_str("gate_memory", "20").unwrap();
        assert_eq!(p.gate.gate_memory, 20.0);
        p.set_str("scaling.scaling_mode", "closed-form").unwrap();
        assert_eq!(p.scaling.scaling_mode, ScalingMode::ClosedForm);
        // Numbers keep their bits through text (as `--set` parsed them before).
        p.set_str("epsilon", "0.1").unwrap();
        assert_eq!(p.gate.epsilon.to_bits(), "0.1".parse::<f64>().unwrap().to_bits());
    }

    /// A value to set: typed and as text, whether the key's declared type and range admit
    /// it, and what `get` returns after it is set.
    #[derive(Debug, Clone)]
    struct Case {
        value: ParamValue,
        text: String,
        admissible: bool,
        back: ParamValue,
    }

    /// Values of every type a key can have, admissible or not: numbers over the whole
    /// `f64` line and around the unit interval, counts around their ranges, switches,
    /// enums' names, factor names, and text that is none of these.
    fn cases(k: &'static Key) -> BoxedStrategy<Case> {
        use proptest::prelude::*;
        let other = "\\?[a-z]{0,6}".prop_map(|s| Case {
            value: ParamValue::Name(s.clone()),
            text: s,
            admissible: false,
            back: ParamValue::Bool(false),
        });
        let bound = k.bound;
        match k.kind {
            ValueKind::Number => {
                let b = bound.unwrap();
                let x = prop_oneof![
                    proptest::num::f64::ANY,
                    -2.0..2.0f64,
                    Just(f64::INFINITY),
                    Just(0.0),
                    Just(1.0)
                ];
                let number = x.prop_map(move |x| Case {
                    value: ParamValue::Number(x),
                    text: x.to_string(),
                    admissible: b.admits(x),
                    back: ParamValue::Number(x),
                });
                prop_oneof![4 => number, 1 => other].boxed()
            }
            ValueKind::Whole => {
                let b = bound.unwrap();
                let n = prop_oneof![-5i64..20_000, any::<i64>()];
                let whole = n.prop_map(move |n| Case {
                    value: ParamValue::Int(n),
                    text: n.to_string(),
                    admissible: b.admits(n as f64),
                    back: ParamValue::Int(n),
                });
                prop_oneof![4 => whole, 1 => other].boxed()
            }
            ValueKind::Switch => {
                let switch = any::<bool>().prop_map(|b| Case {
                    value: ParamValue::Bool(b),
                    text: b.to_string(),
                    admissible: true,
                    back: ParamValue::Bool(b),
                });
                prop_oneof![switch, other].boxed()
            }
            ValueKind::OneOf(names) => {
                let name = proptest::sample::select(names).prop_map(|n| Case {
                    value: ParamValue::Name(n.into()),
                    text: n.into(),
                    admissible: true,
                    back: ParamValue::Name(n.into()),
                });
                prop_oneof![name, other].boxed()
            }
            ValueKind::Text => {
                let list = k.range != NameRule::Factor.range();
                let name = "[A-Za-z_][a-z0-9_]{0,3}".prop_filter("`none` is the empty list", |s| s != "none");
                let names = proptest::collection::btree_set(name, 1..4);
                let good = names.prop_map(move |set| {
                    let names: Vec<String> = set.into_iter().collect();
                    let s = if list { names.join("+") } else { names[0].clone() };
                    Case {
                        value: ParamValue::Name(s.clone()),
                        text: s.clone(),
                        admissible: true,
                        back: ParamValue::Name(s),
                    }
                });
                let bad = ("[a-z]{1,3}", 0..3usize).prop_map(|(a, form)| {
                    let s = [format!("{a}+{a}"), format!("{a} x"), format!("{a}++x")][form].clone();
                    Case {
                        value: ParamValue::Name(s.clone()),
                        text: s,
                        admissible: false,
                        back: ParamValue::Bool(false),
                    }
                });
                prop_oneof![good, bad].boxed()
            }
        }
    }

    fn setting() -> impl proptest::strategy::Strategy<Value = (&'static Key, Case)> {
        use proptest::prelude::*;
        (0..keys().len()).prop_flat_map(|i| {
            let k = &keys()[i];
            cases(k).prop_map(move |c| (k, c))
        })
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(2000))]

        /// For every key, an admissible value (typed or as text) is set and read back; an
        /// inadmissible one is refused with an error naming the key, what is allowed (the
        /// declared range, the enum's names) and the value, and changes nothing.
        #[test]
        fn set_then_get_returns_every_admissible_value_and_refuses_the_rest((k, case) in setting()) {
            let base = ScaledParams::default();
            let (mut typed, mut text) = (base.clone(), base.clone());
            let by_value = typed.set(&k.name, case.value.clone());
            let by_text = text.set_str(&k.dotted(), &case.text);
            if case.admissible {
                by_value.unwrap();
                by_text.unwrap();
                proptest::prop_assert_eq!(typed.get(&k.name).unwrap(), case.back.clone());
                proptest::prop_assert_eq!(text.get(&k.name).unwrap(), case.back);
            } else {
                let allowed = match k.kind {
                    ValueKind::OneOf(names) => names.join(", "),
                    ValueKind::Switch => "true or false".into(),
                    _ => k.range.unwrap().to_string(),
                };
                for (e, given) in [(by_value.unwrap_err(), case.value.to_string()), (by_text.unwrap_err(), case.text)] {
                    let e = e.to_string();
                    proptest::prop_assert!(e.contains(&format!("`{}`", k.name)) || e.contains(&format!("`{}`", k.dotted())), "{}", e);
                    proptest::prop_assert!(e.contains(&allowed) && e.contains(&format!("= {given} ")), "{}", e);
                }
                proptest::prop_assert_eq!(&typed, &base);
                proptest::prop_assert_eq!(&text, &base);
            }
        }
    }

    /// The enums' declared names are the names serde reads and writes.
    #[test]
    fn declared_enum_names_are_the_serialized_names() {
        let p = ScaledParams::default();
        for k in keys() {
            let ValueKind::OneOf(names) = k.kind else { continue };
            for name in names {
                let mut q = p.clone();
                q.set_str(&k.name, name).unwrap();
                let json = serde_json::to_value(&q).unwrap();
                assert_eq!(json[&k.group][&k.name], serde_json::json!(name), "{}", k.name);
                let back: ScaledParams = serde_json::from_value(json).unwrap();
                assert_eq!(back, q);
            }
        }
    }
}
