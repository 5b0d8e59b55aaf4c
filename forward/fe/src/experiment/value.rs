//! How a [`Value`] is read: a number, a `{ start = .. }` table or a keyword,
//! with an error that says which of the three was expected (an untagged
//! enum would only say that nothing matched) and names an unknown key of
//! the table.

use std::fmt;

use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::Deserialize;

use super::{ParamValue, Value};

/// What a value may be, for error messages.
pub const EXPECTED: &str = "a number, { start = .. } (with optional fit, lower, upper, nuisance) or \"bonded\"/\"frictionless\"";

/// The keys of a `{ start = .. }` table.
pub const PARAM_KEYS: [&str; 5] = ["start", "fit", "lower", "upper", "nuisance"];

/// The keywords a value may be.
pub const KEYWORDS: [&str; 2] = ["bonded", "frictionless"];

struct ValueVisitor;

impl<'de> Visitor<'de> for ValueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(EXPECTED)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Value, E> {
        Ok(Value::Fixed(v))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Fixed(v as f64))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Fixed(v as f64))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Value, E> {
        if KEYWORDS.contains(&v) {
            Ok(Value::Keyword(v.to_string()))
        } else {
            Err(E::custom(format!("`{v}`: expected {EXPECTED}")))
        }
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut start: Option<f64> = None;
        let mut p = ParamValue {
            start: 0.0,
            fit: true,
            lower: None,
            upper: None,
            nuisance: false,
        };
        let mut seen: Vec<String> = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if seen.contains(&key) {
                return Err(de::Error::custom(format!("`{key}` is given twice")));
            }
            match key.as_str() {
                "start" => start = Some(map.next_value::<Number>()?.0),
                "lower" => p.lower = Some(map.next_value::<Number>()?.0),
                "upper" => p.upper = Some(map.next_value::<Number>()?.0),
                "fit" => p.fit = map.next_value()?,
                "nuisance" => p.nuisance = map.next_value()?,
                _ => {
                    return Err(de::Error::custom(format!(
                        "unknown key `{key}` in {{ .. }}: expected {}",
                        PARAM_KEYS.join(", ")
                    )))
                }
            }
            seen.push(key);
        }
        match start {
            Some(s) => {
                p.start = s;
                Ok(Value::Param(p))
            }
            None => Err(de::Error::custom(
                "{ .. } without `start`: a parameter needs its start, e.g. { start = 0.3 }",
            )),
        }
    }
}

/// A number, integer or float, as f64 (with an error that says so).
struct Number(f64);

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Number, E> {
                Ok(Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number(v as f64))
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for Value {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ValueVisitor)
    }
}
