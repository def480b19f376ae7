//! Options that take one of a few named values. Each such enum has one name table; from it
//! come parsing (`FromStr`), printing (`Display`), serde, the C interface's codes (a value's
//! place in the table, checked against `include/voxelkit.h` by a test) and the error that
//! lists the choices, so no front end spells a choice or its error on its own.

/// An enum whose values are named by one table.
pub trait Choice: Copy + PartialEq + Sized + 'static {
    /// What the option is called in errors: `separability`, `the fill method`.
    const WHAT: &'static str;
    /// Every value with its name, in the order of the C interface's codes.
    const NAMES: &'static [(&'static str, Self)];

    /// The value's name.
    fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("", |(n, _)| n)
    }

    /// Every name, in table order.
    fn names() -> Vec<&'static str> {
        Self::NAMES.iter().map(|(n, _)| *n).collect()
    }

    /// The names as prose: `a, b or c`.
    fn choices_text() -> String {
        let names = Self::names();
        match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => names.join(""),
        }
    }

    /// The value named `s` (letter case ignored), or the error that lists the choices.
    fn parse_choice(s: &str) -> Result<Self, String> {
        Self::NAMES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(s.trim()))
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("{} must be {}, not `{s}`", Self::WHAT, Self::choices_text()))
    }

    /// The value named by a number (separability 26).
    fn from_number(n: i64) -> Result<Self, String> {
        Self::parse_choice(&n.to_string())
    }

    /// The value of a C interface code (its place in the table).
    fn from_code(code: i64) -> Result<Self, String> {
        usize::try_from(code)
            .ok()
            .and_then(|i| Self::NAMES.get(i))
            .map(|(_, v)| *v)
            .ok_or_else(|| {
                format!(
                    "{} must be {} (codes 0 to {}), not code {code}",
                    Self::WHAT,
                    Self::choices_text(),
                    Self::NAMES.len() - 1
                )
            })
    }

    /// The value's C interface code.
    fn code(self) -> i64 {
        Self::NAMES
            .iter()
            .position(|(_, v)| *v == self)
            .map_or(-1, |i| i as i64)
    }
}

/// A type's name table (`Type, "what it is called": "name" => Variant, ...`) as its `Choice`
/// impl, with `FromStr`, `Display`, `Serialize` and `Deserialize` from it. A choice
/// deserializes from its name, or from an integer where its names are numbers
/// (separability 26).
#[macro_export]
macro_rules! named_choices {
    ($t:ident, $what:literal: $($name:literal => $v:ident),+ $(,)?) => {
        impl $crate::choice::Choice for $t {
            const WHAT: &'static str = $what;
            const NAMES: &'static [(&'static str, Self)] = &[$(($name, $t::$v)),+];
        }
        impl ::std::str::FromStr for $t {
            type Err = String;
            fn from_str(s: &str) -> ::std::result::Result<Self, String> {
                <$t as $crate::choice::Choice>::parse_choice(s)
            }
        }
        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::choice::Choice::name(*self))
            }
        }
        impl ::serde::Serialize for $t {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> ::std::result::Result<S::Ok, S::Error> {
                $crate::choice::serialize_choice(*self, s)
            }
        }
        impl<'de> ::serde::Deserialize<'de> for $t {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> ::std::result::Result<Self, D::Error> {
                $crate::choice::deserialize_choice(d)
            }
        }
    };
}

/// A choice as its name, or as a number where its names are numbers.
pub fn serialize_choice<T: Choice, S: serde::Serializer>(v: T, s: S) -> Result<S::Ok, S::Error> {
    match v.name().parse::<u64>() {
        Ok(n) => s.serialize_u64(n),
        Err(_) => s.serialize_str(v.name()),
    }
}

pub fn deserialize_choice<'de, T: Choice, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<T, D::Error> {
    struct Visit<T>(std::marker::PhantomData<T>);
    impl<T: Choice> serde::de::Visitor<'_> for Visit<T> {
        type Value = T;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "{} ({})", T::WHAT, T::choices_text())
        }
        fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<T, E> {
            T::parse_choice(s).map_err(E::custom)
        }
        fn visit_i64<E: serde::de::Error>(self, n: i64) -> Result<T, E> {
            T::from_number(n).map_err(E::custom)
        }
        fn visit_u64<E: serde::de::Error>(self, n: u64) -> Result<T, E> {
            T::parse_choice(&n.to_string()).map_err(E::custom)
        }
    }
    d.deserialize_any(Visit(std::marker::PhantomData))
}

#[cfg(test)]
mod tests {
    use super::Choice;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Three {
        A,
        B,
        C,
    }
    impl Choice for Three {
        const WHAT: &'static str = "the letter";
        const NAMES: &'static [(&'static str, Self)] =
            &[("a", Three::A), ("b", Three::B), ("c", Three::C)];
    }

    #[test]
    fn names_parse_print_and_list_the_choices_in_errors() {
        assert_eq!(Three::parse_choice("B"), Ok(Three::B));
        assert_eq!(Three::C.name(), "c");
        assert_eq!(
            Three::parse_choice("d").unwrap_err(),
            "the letter must be a, b or c, not `d`"
        );
        assert_eq!(Three::from_code(1), Ok(Three::B));
        assert_eq!(Three::C.code(), 2);
        assert_eq!(
            Three::from_code(3).unwrap_err(),
            "the letter must be a, b or c (codes 0 to 2), not code 3"
        );
        assert!(Three::from_code(-1).is_err());
    }
}
