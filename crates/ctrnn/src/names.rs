//! Settings that are one of a few names (`"euler"`, `"rank"`, `"mutants"`, ...), read from text
//! the way files spell them: one parser, serde's, so a name means the same everywhere.

use serde::de::value::{Error as NameError, StrDeserializer};
use serde::de::{DeserializeOwned, IntoDeserializer};

/// Reads `text` as a `T` spelt as in files, or says what `setting` may be.
///
/// # Example
/// ```
/// use ctrnn::{names::parse_name, Method};
/// assert_eq!(parse_name::<Method>("method", "rk4"), Ok(Method::Rk4));
/// assert_eq!(
///     parse_name::<Method>("method", "rk5").unwrap_err(),
///     r#"method is "rk5"; expected "euler" or "rk4""#
/// );
/// ```
pub fn parse_name<T: DeserializeOwned>(setting: &str, text: &str) -> Result<T, String> {
    let de: StrDeserializer<'_, NameError> = text.into_deserializer();
    T::deserialize(de).map_err(|e| {
        // serde says "unknown variant `x`, expected `a` or `b`"; keep what is expected.
        let e = e.to_string();
        let expected = e.find("expected ").map_or(e.as_str(), |at| &e[at..]);
        format!("{setting} is {text:?}; {}", expected.replace('`', "\""))
    })
}
