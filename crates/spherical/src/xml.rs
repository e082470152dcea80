//! The little XML that V1's GSpherical and GPano's XMP need: a property's text, found as an
//! element (`<GPano:FullPanoWidthPixels>4096</GPano:FullPanoWidthPixels>`) or an attribute
//! (`GPano:FullPanoWidthPixels="4096"`, as ExifTool and many cameras write XMP), under any
//! namespace prefix; and escaping for what is written.

/// The text of the first element or attribute whose local name is `local` (after any
/// `prefix:`), trimmed. Empty elements and closing tags are passed over.
pub fn value<'a>(xml: &'a str, local: &str) -> Option<&'a str> {
    let mut from = 0;
    while let Some(i) = xml[from..].find(local) {
        let at = from + i;
        from = at + local.len();
        let name_start = xml[..at]
            .rfind(|c: char| !(c.is_alphanumeric() || matches!(c, ':' | '_' | '-' | '.')))
            .map_or(0, |p| p + 1);
        let qualified = &xml[name_start..at];
        if !(qualified.is_empty() || qualified.ends_with(':')) {
            continue; // `local` is the end of a longer name
        }
        let after = &xml[from..];
        let opener = xml[..name_start].chars().next_back();
        let found = match opener {
            Some('<') => element_text(after),
            Some(c) if c.is_whitespace() => attribute_value(after),
            _ => None,
        };
        if let Some(v) = found {
            return Some(v.trim());
        }
    }
    None
}

/// An element's text, from just after its name: attributes skipped, up to the next tag.
fn element_text(after: &str) -> Option<&str> {
    if !(after.starts_with('>') || after.starts_with(char::is_whitespace)) {
        return None;
    }
    let close = after.find('>')?;
    if after[..close].ends_with('/') {
        return None; // `<x/>`: no text
    }
    let text = &after[close + 1..];
    Some(&text[..text.find('<')?])
}

/// An attribute's value, from just after its name: `="…"` or `='…'`.
fn attribute_value(after: &str) -> Option<&str> {
    let rest = after.trim_start().strip_prefix('=')?.trim_start();
    let quote = rest.chars().next().filter(|q| *q == '"' || *q == '\'')?;
    let rest = &rest[1..];
    Some(&rest[..rest.find(quote)?])
}

/// `text` with `&`, `<`, `>`, `"` and `'` escaped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_and_attributes_under_any_prefix() {
        let x = r#"<rdf:Description rdf:about="" GPano:ProjectionType='equirectangular'
            xmlns:GPano="http://ns.google.com/photos/1.0/panorama/">
            <GPano:FullPanoWidthPixels> 4096 </GPano:FullPanoWidthPixels>
            <p:CroppedAreaLeftPixels attr="1">12</p:CroppedAreaLeftPixels>
            <GPano:Empty/><GPano:Stitched>true</GPano:Stitched></rdf:Description>"#;
        assert_eq!(value(x, "ProjectionType"), Some("equirectangular"));
        assert_eq!(value(x, "FullPanoWidthPixels"), Some("4096"));
        assert_eq!(value(x, "CroppedAreaLeftPixels"), Some("12"));
        assert_eq!(value(x, "Stitched"), Some("true"));
        assert_eq!(value(x, "Empty"), None);
        assert_eq!(value(x, "PanoWidthPixels"), None); // only whole names
        assert_eq!(value(x, "Missing"), None);
        assert_eq!(escape("a<b & 'c'"), "a&lt;b &amp; &apos;c&apos;");
    }
}
