//! Typed option tables: `[options.NAME]` in a scene file and `--opt NAME.KEY=VALUE` on the
//! command line, read into one struct per method (and one for `gpu`).
//!
//! Each table is declared once, with the crate's `option_table!` macro: the declaration is the
//! struct a method reads (a field per key, with its type, the values it accepts, its default
//! and a doc line), the parser that fills it ([`OptionTable::read`]) and what
//! `penumbra list --options` prints ([`listing`]; as Markdown, the page `docs/options.md`:
//! [`markdown`]), so they cannot disagree. Choices are enums whose spellings are declared once
//! with `option_names!`.
//!
//! * **Keys** are kebab-case: the field `slope_bias` is the key `slope-bias` ([`key_name`]). An
//!   unknown key is an error that names the valid keys, and the one meant when it is close
//!   (`map_size` → `map-size`).
//! * **Values** are read from their text ([`OptionValue::text`]), so a scene file and `--opt`
//!   agree: `li = 12`, `li = "12"` and `--opt pw2002.li=12` are the same value, and a number key
//!   takes an integer (`bias = 4`); an integer key does not take `4.0`.
//! * **Errors** name where the value was written ([`Scene::option_error`]: `options.NAME.KEY` of
//!   the scene file, or the `--opt NAME.KEY=VALUE` argument), the bad value and what the key
//!   accepts.
//!
//! [`OptionValue::text`]: crate::scene::OptionValue::text

use crate::error::InputError;
use crate::scene::Scene;
use std::ops::RangeInclusive;

/// What a key accepts, as error messages and the listing say it.
#[derive(Debug, Clone, PartialEq)]
pub enum Accepted {
    /// One of these spellings.
    OneOf(Vec<String>),
    /// An integer in this inclusive range.
    Integer(u64, u64),
    /// A power of two in this inclusive range.
    PowerOfTwo(u64, u64),
    /// A number (an integer or a float) in this inclusive range.
    Number(f64, f64),
}

impl Accepted {
    /// As the listing shows it: `16 | 12 | 8`, `integer 1..=4096`, `number 0..=1000`.
    pub fn listed(&self) -> String {
        match self {
            Accepted::OneOf(names) => names.join(" | "),
            Accepted::Integer(lo, hi) => format!("integer {lo}..={hi}"),
            Accepted::PowerOfTwo(lo, hi) => format!("power of two {lo}..={hi}"),
            Accepted::Number(lo, hi) => format!("number {lo}..={hi}"),
        }
    }

    /// As an error message says what was expected: `one of 16, 12, 8`,
    /// `an integer in 1..=4096`.
    pub fn expected(&self) -> String {
        match self {
            Accepted::OneOf(names) => format!("one of {}", names.join(", ")),
            Accepted::Integer(lo, hi) => format!("an integer in {lo}..={hi}"),
            Accepted::PowerOfTwo(lo, hi) => format!("a power of two in {lo}..={hi}"),
            Accepted::Number(lo, hi) => format!("a number in {lo}..={hi}"),
        }
    }
}

/// The type of a key's value: how its text is read, what it accepts and how it is written.
pub trait OptionType: Copy {
    /// What a declaration may restrict the key to: a range for numbers, a list of values for
    /// choices.
    type Allowed;
    /// Everything the type can hold, for a key declared without a restriction.
    fn everything() -> Self::Allowed;
    /// The value `text` spells, if `allowed` admits it.
    fn read(text: &str, allowed: &Self::Allowed) -> Option<Self>;
    /// What `allowed` admits.
    fn accepted(allowed: &Self::Allowed) -> Accepted;
    /// The value as a user writes it; reading this text gives the value back.
    fn written(self) -> String;
}

/// [`OptionType`] of unsigned integers: decimal text, within a range.
macro_rules! integer_option_type {
    ($($t:ty),*) => {$(
        impl OptionType for $t {
            type Allowed = RangeInclusive<$t>;
            fn everything() -> Self::Allowed {
                <$t>::MIN..=<$t>::MAX
            }
            fn read(text: &str, allowed: &Self::Allowed) -> Option<Self> {
                text.parse().ok().filter(|v| allowed.contains(v))
            }
            fn accepted(allowed: &Self::Allowed) -> Accepted {
                Accepted::Integer(u64::from(*allowed.start()), u64::from(*allowed.end()))
            }
            fn written(self) -> String {
                self.to_string()
            }
        }
    )*};
}

integer_option_type!(u32, u64);

impl OptionType for f64 {
    type Allowed = RangeInclusive<f64>;
    fn everything() -> Self::Allowed {
        f64::MIN..=f64::MAX
    }
    /// An integer or a float (`4`, `4.5`, `1e3`); NaN is never in range.
    fn read(text: &str, allowed: &Self::Allowed) -> Option<Self> {
        text.parse().ok().filter(|v| allowed.contains(v))
    }
    fn accepted(allowed: &Self::Allowed) -> Accepted {
        Accepted::Number(*allowed.start(), *allowed.end())
    }
    /// Rust's shortest text that reads back to the same bits (`4`, `0.1`).
    fn written(self) -> String {
        self.to_string()
    }
}

/// A key whose default the scene decides (`None` until the key is written).
impl<T: OptionType> OptionType for Option<T> {
    type Allowed = T::Allowed;
    fn everything() -> Self::Allowed {
        T::everything()
    }
    fn read(text: &str, allowed: &Self::Allowed) -> Option<Self> {
        T::read(text, allowed).map(Some)
    }
    fn accepted(allowed: &Self::Allowed) -> Accepted {
        T::accepted(allowed)
    }
    /// The value's text; empty for `None` (the listing shows the scene's rule instead).
    fn written(self) -> String {
        self.map_or_else(String::new, T::written)
    }
}

/// An integer that must be a power of two (`[options.gpu] tile-size`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PowerOfTwo(pub u32);

impl OptionType for PowerOfTwo {
    type Allowed = RangeInclusive<u32>;
    fn everything() -> Self::Allowed {
        1..=1 << 31
    }
    fn read(text: &str, allowed: &Self::Allowed) -> Option<Self> {
        u32::read(text, allowed)
            .filter(|v| v.is_power_of_two())
            .map(PowerOfTwo)
    }
    fn accepted(allowed: &Self::Allowed) -> Accepted {
        Accepted::PowerOfTwo(u64::from(*allowed.start()), u64::from(*allowed.end()))
    }
    fn written(self) -> String {
        self.0.to_string()
    }
}

/// Declares the option spellings of an enum's variants, `option_names!(Filter { Nearest =
/// "nearest", Bilinear = "bilinear" })`: its [`OptionType`], every variant allowed unless a key
/// restricts them. Given a whole enum declaration with a spelling after each variant, it
/// declares the enum too (`Debug, Clone, Copy, PartialEq, Eq`).
macro_rules! option_names {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $($(#[doc = $doc:literal])* $variant:ident = $text:literal,)+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum $name {
            $($(#[doc = $doc])* $variant,)+
        }

        $crate::options::option_names!($name { $($variant = $text),+ });
    };
    ($ty:ty { $($variant:ident = $text:literal),+ $(,)? }) => {
        impl $crate::options::OptionType for $ty {
            type Allowed = &'static [$ty];
            fn everything() -> Self::Allowed {
                &[$(Self::$variant),+]
            }
            fn read(text: &str, allowed: &Self::Allowed) -> Option<Self> {
                allowed
                    .iter()
                    .copied()
                    .find(|v| $crate::options::OptionType::written(*v) == text)
            }
            fn accepted(allowed: &Self::Allowed) -> $crate::options::Accepted {
                $crate::options::Accepted::OneOf(
                    allowed
                        .iter()
                        .map(|v| $crate::options::OptionType::written(*v))
                        .collect(),
                )
            }
            fn written(self) -> String {
                match self {
                    $(Self::$variant => $text,)+
                }
                .to_string()
            }
        }
    };
}
pub(crate) use option_names;

option_names! {
    /// An `on | off` key.
    pub enum Switch {
        /// On.
        On = "on",
        /// Off.
        Off = "off",
    }
}

impl Switch {
    /// Whether it is on.
    pub fn is_on(self) -> bool {
        self == Switch::On
    }
}

/// The default of a key, as the listing shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DefaultValue {
    /// This value, written as a user writes it.
    Written(String),
    /// Decided by the scene, as this text says (e.g. the image's larger side).
    FromScene(String),
}

/// One key of a table, as the listing shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyDoc {
    /// The key, kebab-case.
    pub key: String,
    /// What it accepts.
    pub accepted: Accepted,
    /// Its default.
    pub default: DefaultValue,
    /// What it means: its doc comment, on one line.
    pub meaning: String,
}

/// The key of a struct field: its name with `-` for `_` (`slope_bias` → `slope-bias`).
pub fn key_name(field: &str) -> String {
    field.replace('_', "-")
}

/// Keys read into a struct: a whole table ([`OptionTable`]) or a group of keys that several
/// tables share (`option_table!` writes both).
pub trait OptionSet: Default {
    /// Appends every key's documentation to `keys`, in declaration order.
    fn document(keys: &mut Vec<KeyDoc>);
    /// Sets `key` from its written `text`: `None` when there is no such key, else `Ok`, or what
    /// the key accepts when `text` is not one of them.
    fn set(&mut self, key: &str, text: &str) -> Option<Result<(), Accepted>>;
}

/// A whole option table, `[options.NAME]`.
pub trait OptionTable: OptionSet {
    /// The table's name: a method, or `gpu`.
    const NAME: &'static str;

    /// Every key of the table, in declaration order.
    fn keys() -> Vec<KeyDoc> {
        let mut keys = Vec::new();
        Self::document(&mut keys);
        keys
    }

    /// The table as `scene` writes it, defaults for the keys it leaves out. The first bad key
    /// (in key order) is an error naming where it was written and either the bad value and
    /// what the key accepts, or the valid keys.
    fn read(scene: &Scene) -> Result<Self, InputError> {
        let mut table = Self::default();
        for (key, value) in scene.options.get(Self::NAME).into_iter().flatten() {
            let message = match table.set(key, &value.text()) {
                Some(Ok(())) => continue,
                Some(Err(accepted)) => {
                    format!("invalid value {value}; expected {}", accepted.expected())
                }
                None => unknown_key(Self::NAME, key, &Self::keys()),
            };
            return Err(scene.option_error(Self::NAME, key, message));
        }
        Ok(table)
    }

    /// [`OptionTable::read`] without its result: whether the table reads (the check the
    /// registry runs on every table a scene writes, `crate::methods::check_option_tables`).
    fn check(scene: &Scene) -> Result<(), InputError> {
        Self::read(scene).map(drop)
    }

    /// Whether `scene` writes `key` (for a key that cannot act in some configuration, which is
    /// then an error rather than ignored).
    fn is_written(scene: &Scene, key: &str) -> bool {
        debug_assert!(
            Self::keys().iter().any(|k| k.key == key),
            "{key} is no key of [options.{}]",
            Self::NAME
        );
        scene
            .options
            .get(Self::NAME)
            .is_some_and(|t| t.contains_key(key))
    }
}

/// Declares an option table, or a group of keys several tables share, as one struct:
///
/// ```text
/// option_table! {
///     /// The struct's doc.
///     pub struct NsampleOptions["nsample"] {   // ["NAME"]: a whole table; none: a group
///         ..shadow: HardSvOptions,             // a group (or table) whose keys this one has too
///         /// The key's meaning, one line.
///         n: u32 [1..=4096] = 1024;            // [allowed] is optional
///         /// Another key, whose default the scene decides.
///         map_size: Option<u32> [8..=4096] = None, scene "the image's larger side";
///     }
/// }
/// ```
macro_rules! option_table {
    (@allowed $ty:ty) => {
        <$ty as $crate::options::OptionType>::everything()
    };
    (@allowed $ty:ty, $allowed:expr) => {
        $allowed
    };
    (@default $ty:ty, $default:expr) => {
        $crate::options::DefaultValue::Written(<$ty as $crate::options::OptionType>::written(
            $default,
        ))
    };
    (@default $ty:ty, $default:expr, $scene:expr) => {
        $crate::options::DefaultValue::FromScene(($scene).to_string())
    };
    (@table $name:ident $table:literal) => {
        impl $crate::options::OptionTable for $name {
            const NAME: &'static str = $table;
        }
    };
    (@table $name:ident) => {};
    (
        $(#[$meta:meta])*
        pub struct $name:ident $([$table:literal])? {
            $(..$group:ident: $gty:ty,)*
            $(
                $(#[doc = $doc:literal])+
                $field:ident: $ty:ty $([$allowed:expr])? = $default:expr $(, scene $scene:expr)?;
            )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct $name {
            $(
                #[doc = concat!("The keys of [`", stringify!($gty), "`].")]
                pub $group: $gty,
            )*
            $(
                $(#[doc = $doc])+
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self {
                    $($group: Default::default(),)*
                    $($field: $default,)*
                }
            }
        }

        impl $crate::options::OptionSet for $name {
            fn document(keys: &mut Vec<$crate::options::KeyDoc>) {
                $(<$gty as $crate::options::OptionSet>::document(keys);)*
                $(
                    let allowed: <$ty as $crate::options::OptionType>::Allowed =
                        $crate::options::option_table!(@allowed $ty $(, $allowed)?);
                    keys.push($crate::options::KeyDoc {
                        key: $crate::options::key_name(stringify!($field)),
                        accepted: <$ty as $crate::options::OptionType>::accepted(&allowed),
                        default: $crate::options::option_table!(
                            @default $ty, $default $(, $scene)?
                        ),
                        meaning: concat!($($doc),+).trim().to_string(),
                    });
                )*
            }

            fn set(
                &mut self,
                key: &str,
                text: &str,
            ) -> Option<Result<(), $crate::options::Accepted>> {
                $(
                    if let Some(r) = $crate::options::OptionSet::set(&mut self.$group, key, text) {
                        return Some(r);
                    }
                )*
                $(
                    if key == $crate::options::key_name(stringify!($field)) {
                        let allowed: <$ty as $crate::options::OptionType>::Allowed =
                            $crate::options::option_table!(@allowed $ty $(, $allowed)?);
                        return Some(
                            match <$ty as $crate::options::OptionType>::read(text, &allowed) {
                                Some(v) => {
                                    self.$field = v;
                                    Ok(())
                                }
                                None => {
                                    Err(<$ty as $crate::options::OptionType>::accepted(&allowed))
                                }
                            },
                        );
                    }
                )*
                None
            }
        }

        $crate::options::option_table!(@table $name $($table)?);
    };
}
pub(crate) use option_table;

/// The message for `key`, which table `table` (with `keys`) does not have: the key meant when
/// it is close, and the valid keys.
fn unknown_key(table: &str, key: &str, keys: &[KeyDoc]) -> String {
    let valid: Vec<&str> = keys.iter().map(|k| k.key.as_str()).collect();
    let meant = closest(key, &valid)
        .map(|k| format!("did you mean {k}? "))
        .unwrap_or_default();
    format!(
        "unknown option {key} for {table}; {meant}valid: {}",
        valid.join(", ")
    )
}

/// The valid key `key` most likely means: the same key in kebab-case and lower case, else the
/// nearest within two edits (a swap of two letters is two) when that is at most half the key.
fn closest<'a>(key: &str, valid: &[&'a str]) -> Option<&'a str> {
    let written = key.to_lowercase().replace('_', "-");
    valid
        .iter()
        .map(|v| (edit_distance(&written, v), *v))
        .filter(|&(d, _)| d <= 2 && 2 * d <= written.chars().count())
        .min_by_key(|&(d, _)| d)
        .map(|(_, v)| v)
}

/// The Levenshtein distance between `a` and `b`, in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substituted = diagonal + usize::from(ca != *cb);
            diagonal = row[j + 1];
            row[j + 1] = substituted.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

/// What `penumbra list --options` prints for `tables` (each a name and its keys): a header
/// `[options.NAME]` per table, then per key `  KEY = ACCEPTED  (default: D)` and its meaning
/// on the next line.
pub fn listing(tables: &[(&str, Vec<KeyDoc>)]) -> String {
    let mut out = String::new();
    for (k, (name, keys)) in tables.iter().enumerate() {
        if k > 0 {
            out.push('\n');
        }
        out += &format!("[options.{name}]\n");
        for key in keys {
            let default = match &key.default {
                DefaultValue::Written(v) => v,
                DefaultValue::FromScene(rule) => rule,
            };
            out += &format!(
                "  {} = {}  (default: {default})\n      {}\n",
                key.key,
                key.accepted.listed(),
                key.meaning
            );
        }
    }
    out
}

/// `docs/options.md`: what [`listing`] prints for `tables`, as Markdown (`penumbra list
/// --options --markdown`), under a header saying how the page is made and where the keys'
/// syntax and their meaning in each method are described: a section per table, a row per key
/// (key, values accepted, default, meaning). A `|` in a cell is escaped (`\|`), so that it
/// does not end the cell (GitHub-flavoured Markdown).
pub fn markdown(tables: &[(&str, Vec<KeyDoc>)]) -> String {
    let cell = |text: &str| text.replace('|', "\\|");
    let mut out = String::from(concat!(
        "# Options\n\n",
        "<!-- Generated from the option tables' declarations by ",
        "`cargo run --release -- list --options --markdown > docs/options.md`. ",
        "Do not edit: tests/suite/options.rs fails when this file differs from the code. -->\n\n",
        "Every key of every option table, as `penumbra list --options` prints it. A method's ",
        "keys are set with `[options.METHOD]` in a scene file or `--opt METHOD.KEY=VALUE` on ",
        "the command line, those of every pass with `[options.gpu]`; how values are written ",
        "and checked: [scene-format.md](scene-format.md#options) and [cli.md](cli.md). What ",
        "each method's options do, with their findings: [methods.md](methods.md).\n",
    ));
    for (name, keys) in tables {
        out += &format!(
            "\n## `[options.{name}]`\n\n| key | accepts | default | meaning |\n|---|---|---|---|\n"
        );
        for key in keys {
            let default = match &key.default {
                DefaultValue::Written(v) => format!("`{v}`"),
                DefaultValue::FromScene(rule) => cell(rule),
            };
            out += &format!(
                "| `{}` | {} | {default} | {} |\n",
                key.key,
                cell(&key.accepted.listed()),
                cell(&key.meaning)
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{builtin, OptionValue};

    /// A choice whose spellings are numbers, as `li`'s.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Bits {
        B16,
        B12,
        B8,
    }

    option_names!(Bits {
        B16 = "16",
        B12 = "12",
        B8 = "8",
    });

    option_table! {
        /// A group of keys.
        pub struct Group {
            /// a switch
            corner_wedges: Switch = Switch::On;
        }
    }

    option_table! {
        /// A table of every kind of key.
        pub struct Table["test"] {
            ..group: Group,
            /// bits
            li: Bits [&[Bits::B16, Bits::B12]] = Bits::B16;
            /// a number
            bias: f64 [0.0..=10.0] = 4.0;
            /// an integer
            n: u32 [1..=64] = 8;
            /// a tile
            tile_size: PowerOfTwo [2..=256] = PowerOfTwo(8);
            /// from the scene
            map_size: Option<u32> [8..=4096] = None, scene "the image's side";
        }
    }

    /// A scene whose `[options.test]` holds `pairs`.
    fn scene(pairs: &[(&str, OptionValue)]) -> Scene {
        let mut s = builtin::load("single-quad").unwrap();
        let t = s.options.entry("test".into()).or_default();
        for (k, v) in pairs {
            t.insert(k.to_string(), v.clone());
        }
        s
    }

    fn read(pairs: &[(&str, OptionValue)]) -> Result<Table, String> {
        Table::read(&scene(pairs)).map_err(|e| e.to_string())
    }

    #[test]
    fn values_written_naturally_read_alike() {
        use OptionValue::{Float, Int, Str};
        for v in [Int(12), Str("12".into()), OptionValue::parse_cli("12")] {
            assert_eq!(read(&[("li", v)]).unwrap().li, Bits::B12);
        }
        for (v, x) in [
            (Int(4), 4.0),
            (Str("4".into()), 4.0),
            (Float(2.5), 2.5),
            (OptionValue::parse_cli("1e1"), 10.0),
            (Float(0.1), 0.1),
        ] {
            assert_eq!(
                read(&[("bias", v)]).unwrap().bias.to_bits(),
                f64::to_bits(x)
            );
        }
        let t = read(&[
            ("n", Str("64".into())),
            ("tile-size", Int(256)),
            ("map-size", Int(512)),
            ("corner-wedges", Str("off".into())),
        ])
        .unwrap();
        assert_eq!(
            (t.n, t.tile_size, t.map_size, t.group.corner_wedges),
            (64, PowerOfTwo(256), Some(512), Switch::Off)
        );
        assert_eq!(read(&[]).unwrap(), Table::default());
        assert_eq!(Table::default().map_size, None);
    }

    #[test]
    fn bad_values_name_the_key_the_value_and_what_is_accepted() {
        use OptionValue::{Bool, Float, Int, Str};
        let at = "single-quad: options.test.";
        for (key, v, says) in [
            ("li", Int(8), "li: invalid value 8; expected one of 16, 12"),
            (
                "li",
                Str("16 ".into()),
                "li: invalid value \"16 \"; expected one of 16, 12",
            ),
            (
                "bias",
                Float(10.5),
                "bias: invalid value 10.5; expected a number in 0..=10",
            ),
            (
                "bias",
                Str("nan".into()),
                "bias: invalid value \"nan\"; expected a number",
            ),
            (
                "n",
                Float(8.0),
                "n: invalid value 8.0; expected an integer in 1..=64",
            ),
            (
                "n",
                Int(-1),
                "n: invalid value -1; expected an integer in 1..=64",
            ),
            (
                "n",
                Bool(true),
                "n: invalid value true; expected an integer in 1..=64",
            ),
            (
                "n",
                Int(65),
                "n: invalid value 65; expected an integer in 1..=64",
            ),
            ("tile-size", Int(24), "expected a power of two in 2..=256"),
            (
                "map-size",
                Int(4),
                "map-size: invalid value 4; expected an integer in 8..=4096",
            ),
            ("corner-wedges", Bool(true), "expected one of on, off"),
        ] {
            let e = read(&[(key, v)]).unwrap_err();
            assert!(e.starts_with(at) && e.contains(says), "{key}: {e}");
        }
    }

    #[test]
    fn unknown_keys_name_the_valid_ones_and_the_one_meant() {
        let valid = "valid: corner-wedges, li, bias, n, tile-size, map-size";
        for (key, meant) in [
            ("map_size", Some("map-size")),
            ("Tile_Size", Some("tile-size")),
            ("corner_wedges", Some("corner-wedges")),
            ("bais", Some("bias")),
            ("lii", Some("li")),
            ("x", None),
            ("bogus", None),
        ] {
            let e = read(&[(key, OptionValue::Int(1))]).unwrap_err();
            let hint = meant.map_or(String::new(), |m| format!("did you mean {m}? "));
            assert_eq!(
                e,
                format!(
                    "single-quad: options.test.{key}: unknown option {key} for test; {hint}{valid}"
                )
            );
        }
    }

    /// An option set with `--opt` is named by the argument, one from the file by the file and
    /// the key; `--opt` replaces the file's value.
    #[test]
    fn errors_name_where_the_value_was_written() {
        let mut s = scene(&[("n", OptionValue::Int(0))]);
        let e = Table::read(&s).unwrap_err();
        assert_eq!(
            (e.file.as_str(), e.object.as_deref()),
            ("single-quad", Some("options.test.n"))
        );
        s.set_cli_option("test.n=99").unwrap();
        let e = Table::read(&s).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--opt test.n=99: invalid value 99; expected an integer in 1..=64"
        );
        s.set_cli_option("test.n=9").unwrap();
        assert_eq!(Table::read(&s).unwrap().n, 9);
        for bad in ["test.n", "test=1", ".n=1", "test.=1"] {
            let e = s.set_cli_option(bad).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!("--opt {bad}: expected METHOD.KEY=VALUE")
            );
        }
    }

    #[test]
    fn written_keys_are_known() {
        let s = scene(&[("n", OptionValue::Int(2))]);
        assert!(Table::is_written(&s, "n"));
        assert!(!Table::is_written(&s, "bias"));
    }

    #[test]
    fn the_listing_shows_every_key_its_values_default_and_meaning() {
        assert_eq!(
            listing(&[("test", Table::keys())]),
            "[options.test]\n\
             \x20 corner-wedges = on | off  (default: on)\n      a switch\n\
             \x20 li = 16 | 12  (default: 16)\n      bits\n\
             \x20 bias = number 0..=10  (default: 4)\n      a number\n\
             \x20 n = integer 1..=64  (default: 8)\n      an integer\n\
             \x20 tile-size = power of two 2..=256  (default: 8)\n      a tile\n\
             \x20 map-size = integer 8..=4096  (default: the image's side)\n      from the scene\n"
        );
    }

    #[test]
    fn edit_distances() {
        for (a, b, d) in [
            ("", "", 0),
            ("li", "", 2),
            ("bias", "bais", 2),
            ("kitten", "sitting", 3),
            ("map-size", "map-size", 0),
            ("√n", "n", 1),
        ] {
            assert_eq!(
                (edit_distance(a, b), edit_distance(b, a)),
                (d, d),
                "{a} {b}"
            );
        }
    }
}
