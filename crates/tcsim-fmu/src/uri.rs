//! The `fmuResourceLocation` of `fmi2Instantiate`: a `file` URI (RFC 8089) of the FMU's
//! `resources` folder, to a local path.
//!
//! Accepted forms: `file:///path`, `file:/path`, `file://localhost/path` (and `file:///C:/path` on
//! Windows), fully percent-decoded as UTF-8 (RFC 3986): FMI Library encodes everything but letters,
//! digits and `-_.~/`, so `%20`, `%2B`, `%28`, `%C3%B6` all occur. A URI with another host, a
//! malformed escape or an escape that is not UTF-8 is refused with a message that says why.

/// The local path of a `file` URI (without a trailing `/`), or why it cannot be used.
pub fn resources_path(location: &str) -> Result<String, String> {
    let refuse = |why: &str| Err(format!("fmuResourceLocation {location:?}: {why}"));
    let Some(rest) = location.strip_prefix("file:").or_else(|| location.strip_prefix("FILE:")) else {
        return refuse("expected a file: URI (file:///path, file:/path or file://localhost/path)");
    };
    let path = match rest.strip_prefix("//") {
        // authority form: file://host/path, with an empty host or localhost only
        Some(authority) => {
            let (host, path) = authority.find('/').map_or((authority, ""), |i| authority.split_at(i));
            if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
                return refuse(&format!("host {host:?}: expected a local file (no host, or localhost)"));
            }
            path
        }
        None => rest,
    };
    if !path.starts_with('/') {
        return refuse("expected an absolute path");
    }
    let decoded = match percent_decode(path) {
        Ok(d) => d,
        Err(why) => return refuse(&why),
    };
    // file:///C:/dir on Windows: the drive letter follows the slash
    let b = decoded.as_bytes();
    let local = if b.len() > 2 && b[2] == b':' && b[1].is_ascii_alphabetic() { &decoded[1..] } else { &decoded };
    let trimmed = local.trim_end_matches('/');
    Ok(if trimmed.is_empty() { "/".to_string() } else { trimmed.to_string() })
}

/// Decode every `%XX` escape; the bytes must form UTF-8.
fn percent_decode(text: &str) -> Result<String, String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
            let value = hex.and_then(|h| u8::from_str_radix(h, 16).ok());
            match value {
                Some(v) if hex.is_some_and(|h| h.bytes().all(|c| c.is_ascii_hexdigit())) => out.push(v),
                _ => return Err(format!("malformed percent escape at byte {i}: expected %XX with hex digits")),
            }
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "the percent-decoded path is not UTF-8".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_three_local_forms_and_full_decoding() {
        let want = "/tmp/a b+(ö)/resources";
        for uri in [
            "file:///tmp/a%20b%2B%28%C3%B6%29/resources/",
            "file:/tmp/a%20b%2B%28%C3%B6%29/resources",
            "file://localhost/tmp/a%20b+(%c3%b6)/resources",
            "file:///tmp/a b+(ö)/resources",
        ] {
            assert_eq!(resources_path(uri).as_deref(), Ok(want), "{uri}");
        }
        assert_eq!(resources_path("file:///C:/Users/J%C3%B6rg/r").as_deref(), Ok("C:/Users/Jörg/r"));
    }

    #[test]
    fn other_hosts_bad_escapes_and_other_schemes_are_refused() {
        assert!(resources_path("file://server/share/r").unwrap_err().contains("host \"server\""));
        assert!(resources_path("file:///tmp/a%2").unwrap_err().contains("percent escape"));
        assert!(resources_path("file:///tmp/a%zz").unwrap_err().contains("percent escape"));
        assert!(resources_path("file:///tmp/%FF").unwrap_err().contains("UTF-8"));
        assert!(resources_path("http://x/r").unwrap_err().contains("file: URI"));
        assert!(resources_path("file:relative/r").unwrap_err().contains("absolute"));
    }
}
