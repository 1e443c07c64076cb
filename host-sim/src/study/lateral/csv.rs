//! A CSV cell's text (RFC 4180), for the study's CSV files: the summary
//! per grade and well ([`super::table::csv`]) and every run's stations
//! ([`super::stations::stations_csv`]). A file of its own so that both
//! can use it without either importing the other.

/// A text field quoted when it holds a comma, quote or line break (RFC 4180).
pub(crate) fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_is_quoted_only_when_it_must_be() {
        assert_eq!(csv_field("scc1300"), "scc1300");
        assert_eq!(csv_field(""), "");
        assert_eq!(csv_field("my,plan.json"), "\"my,plan.json\"");
        assert_eq!(csv_field("a \"b\""), "\"a \"\"b\"\"\"");
        assert_eq!(csv_field("two\nlines"), "\"two\nlines\"");
        assert_eq!(csv_field("cr\r"), "\"cr\r\"");
    }
}
