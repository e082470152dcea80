//! Who may talk to the server. It listens on 127.0.0.1 only, but any page the browser
//! shows can send requests to loopback addresses, so every request must also:
//!
//! - carry the token printed in the URL (`?token=…` or the `X-Mirrorball-Token` header):
//!   a page from another site does not know it;
//! - name this server in its `Host` header (`127.0.0.1:PORT` or `localhost:PORT`): a
//!   DNS-rebinding page reaches the port under its own host name, and is refused;
//! - come from this server's own origin if it says where it comes from (`Origin`), and
//!   not say it is cross-site (`Sec-Fetch-Site`).

use axum::http::{HeaderMap, StatusCode};

/// The header a request may carry its token in.
pub const TOKEN_HEADER: &str = "x-mirrorball-token";

/// A fresh token: 128 random bits as 32 hexadecimal digits.
pub fn new_token() -> Result<String, crate::Error> {
    let mut b = [0u8; 16];
    getrandom::fill(&mut b)
        .map_err(|e| crate::Error::system(format!("no random numbers for the token: {e}")))?;
    Ok(b.iter().map(|x| format!("{x:02x}")).collect())
}

/// What a request must match: the server's port and token.
#[derive(Clone, Debug)]
pub struct Guard {
    pub port: u16,
    pub token: String,
}

impl Guard {
    /// `Ok` when the request with `headers` and query string `query` may be served, else the
    /// status and the reason.
    pub fn check(
        &self,
        headers: &HeaderMap,
        query: Option<&str>,
    ) -> Result<(), (StatusCode, String)> {
        let forbidden = |why: &str| Err((StatusCode::FORBIDDEN, why.to_string()));
        let host = headers.get("host").and_then(|h| h.to_str().ok());
        if !host.is_some_and(|h| self.is_own_host(h)) {
            return forbidden("the Host header does not name this server");
        }
        if let Some(o) = headers.get("origin") {
            let own = o.to_str().ok().and_then(|o| o.strip_prefix("http://"));
            if !own.is_some_and(|h| self.is_own_host(h)) {
                return forbidden("requests from other origins are refused");
            }
        }
        if headers
            .get("sec-fetch-site")
            .is_some_and(|s| s.as_bytes() == b"cross-site")
        {
            return forbidden("cross-site requests are refused");
        }
        let from_header = headers.get(TOKEN_HEADER).and_then(|t| t.to_str().ok());
        let from_query = query.and_then(|q| q.split('&').find_map(|kv| kv.strip_prefix("token=")));
        match from_header.or(from_query) {
            Some(t) if same(t.as_bytes(), self.token.as_bytes()) => Ok(()),
            Some(_) => Err((StatusCode::UNAUTHORIZED, "wrong token".into())),
            None => Err((
                StatusCode::UNAUTHORIZED,
                "no token: open the URL the studio printed".into(),
            )),
        }
    }

    /// `127.0.0.1:PORT` or `localhost:PORT` (ASCII case ignored in the name).
    fn is_own_host(&self, h: &str) -> bool {
        let Some((name, port)) = h.rsplit_once(':') else {
            return false;
        };
        port.parse::<u16>().ok() == Some(self.port)
            && (name == "127.0.0.1" || name.eq_ignore_ascii_case("localhost"))
    }
}

/// Compares in time independent of where the first difference is.
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(&'static str, &str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.insert(*k, v.parse().unwrap());
        }
        h
    }

    #[test]
    fn each_rule_refuses_on_its_own() {
        let g = Guard {
            port: 4321,
            token: "abc".into(),
        };
        let good = [("host", "127.0.0.1:4321"), (TOKEN_HEADER, "abc")];
        assert!(g.check(&headers(&good), None).is_ok());
        assert!(g
            .check(
                &headers(&[("host", "localhost:4321")]),
                Some("a=1&token=abc")
            )
            .is_ok());
        for bad in [
            headers(&[("host", "evil.example:4321"), (TOKEN_HEADER, "abc")]),
            headers(&[("host", "127.0.0.1:4322"), (TOKEN_HEADER, "abc")]),
            headers(&[(TOKEN_HEADER, "abc")]),
            headers(&[("host", "127.0.0.1:4321"), (TOKEN_HEADER, "abd")]),
            headers(&[("host", "127.0.0.1:4321"), (TOKEN_HEADER, "ab")]),
            headers(&[("host", "127.0.0.1:4321")]),
            headers(&[
                ("host", "127.0.0.1:4321"),
                (TOKEN_HEADER, "abc"),
                ("origin", "http://evil.example"),
            ]),
            headers(&[
                ("host", "127.0.0.1:4321"),
                (TOKEN_HEADER, "abc"),
                ("origin", "null"),
            ]),
            headers(&[
                ("host", "127.0.0.1:4321"),
                (TOKEN_HEADER, "abc"),
                ("sec-fetch-site", "cross-site"),
            ]),
        ] {
            assert!(g.check(&bad, None).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn tokens_are_fresh_and_hex() {
        let (a, b) = (new_token().unwrap(), new_token().unwrap());
        assert_eq!(a.len(), 32);
        assert!(a.bytes().all(|c| c.is_ascii_hexdigit()));
        assert_ne!(a, b);
    }
}
