//! A state-changing request from the server's own page: an HTML form `POST`ed with
//! `application/x-www-form-urlencoded`, its body read within a bound, and its origin held to the
//! page's own.
//!
//! A `GET` link is no boundary: any page a browser visits can make it follow one (an `<img>`,
//! a redirect, a link), and the browser then sends no `Origin`. A browser always sends
//! `Origin` with a `POST`, and with `Sec-Fetch-Site` says whether the request came from the
//! server's own pages. So a request that changes state is a `POST` whose `Origin` is present
//! (the [`crate::Guard`] has already held it to `http://` and the `Host`) and whose
//! `Sec-Fetch-Site`, when sent, is `same-origin`.

use crate::{Head, percent_decode};
use std::io::Read;
use std::net::TcpStream;

/// Largest form body read, bytes.
pub const MAX_FORM_BYTES: usize = 2048;

/// Why a form was not taken.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FormError {
    /// Not a `POST`.
    #[error("{method} {path} changes state: send it as POST from this server's own page")]
    Method {
        /// The method sent.
        method: String,
        /// The path.
        path: String,
    },
    /// No `Origin` header: not sent by a browser's form on this server's page.
    #[error("a POST without an Origin header is refused: send it from this server's own page")]
    NoOrigin,
    /// `Sec-Fetch-Site` says another site (or the user's address bar) sent it.
    #[error(
        "Sec-Fetch-Site `{got}` is refused: allowed `same-origin` (a request from another site \
         may not change this server's state)"
    )]
    CrossSite {
        /// The value sent.
        got: String,
    },
    /// The body is not a URL-encoded form.
    #[error(
        "Content-Type `{got}` is refused: allowed `application/x-www-form-urlencoded` (an HTML \
         form)"
    )]
    ContentType {
        /// The value sent (empty when absent).
        got: String,
    },
    /// `Content-Length` is missing, not a number, or above [`MAX_FORM_BYTES`].
    #[error("Content-Length `{got}` is refused: allowed 0 to {limit} bytes")]
    Length {
        /// The value sent (empty when absent).
        got: String,
        /// The limit, bytes.
        limit: usize,
    },
    /// The body ended early, timed out, or is not UTF-8 once decoded.
    #[error("the form's body did not arrive whole as UTF-8 text")]
    Body,
}

impl FormError {
    /// The refusal counter it counts under (a [`crate::gate::RefusedCounts`] field).
    pub fn kind(&self) -> &'static str {
        match self {
            FormError::NoOrigin | FormError::CrossSite { .. } => "origin",
            FormError::Length { .. } => "size",
            _ => "head",
        }
    }

    /// The HTTP status to answer with.
    pub fn status(&self) -> &'static str {
        match self {
            FormError::Method { .. } => "405 Method Not Allowed",
            FormError::NoOrigin | FormError::CrossSite { .. } => "403 Forbidden",
            FormError::ContentType { .. } => "415 Unsupported Media Type",
            FormError::Length { .. } => "413 Content Too Large",
            FormError::Body => "400 Bad Request",
        }
    }
}

/// A form's fields, in order, decoded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Form {
    /// `(name, value)` pairs.
    pub fields: Vec<(String, String)>,
}

impl Form {
    /// Parses a URL-encoded form (`a=1&b=x+y`); `None` on a bad escape or non-UTF-8 bytes.
    pub fn parse(body: &str) -> Option<Form> {
        let mut fields = Vec::new();
        for kv in body.split('&').filter(|s| !s.is_empty()) {
            let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
            fields.push((percent_decode(k)?, percent_decode(v)?));
        }
        Some(Form { fields })
    }

    /// The first field `name`.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// Checks that `head` is a state change from this server's own page (see the module's doc):
/// `POST`, an `Origin`, and `Sec-Fetch-Site: same-origin` when it is sent. The `Host` and the
/// `Origin`'s value are the [`crate::Guard`]'s to check, before this.
pub fn check_own_post(head: &Head) -> Result<(), FormError> {
    if head.method != "POST" {
        return Err(FormError::Method {
            method: head.method.clone(),
            path: head.path().to_string(),
        });
    }
    if head.header("origin").is_none() {
        return Err(FormError::NoOrigin);
    }
    match head.header("sec-fetch-site") {
        None | Some("same-origin") => Ok(()),
        Some(other) => Err(FormError::CrossSite {
            got: other.to_string(),
        }),
    }
}

/// The `Content-Length` of a form `POST`, checked: a URL-encoded form of at most
/// [`MAX_FORM_BYTES`].
pub fn form_length(head: &Head) -> Result<usize, FormError> {
    let ctype = head.header("content-type").unwrap_or("");
    let mime = ctype.split(';').next().unwrap_or("").trim();
    if !mime.eq_ignore_ascii_case("application/x-www-form-urlencoded") {
        return Err(FormError::ContentType {
            got: ctype.to_string(),
        });
    }
    let got = head.header("content-length").unwrap_or("");
    match got.parse::<usize>() {
        Ok(n) if n <= MAX_FORM_BYTES && got.bytes().all(|c| c.is_ascii_digit()) => Ok(n),
        _ => Err(FormError::Length {
            got: got.to_string(),
            limit: MAX_FORM_BYTES,
        }),
    }
}

/// Checks `head` ([`check_own_post`], [`form_length`]) and reads its form from `stream`
/// (within the head's read time-out).
pub fn read_own_form(stream: &mut TcpStream, head: &Head) -> Result<Form, FormError> {
    check_own_post(head)?;
    let n = form_length(head)?;
    let mut body = vec![0u8; n];
    stream.read_exact(&mut body).map_err(|_| FormError::Body)?;
    let text = String::from_utf8(body).map_err(|_| FormError::Body)?;
    Form::parse(&text).ok_or(FormError::Body)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parse_head;

    fn head(text: &str) -> Head {
        parse_head(text.replace('\n', "\r\n").as_bytes()).unwrap()
    }

    const FORM: &str = "Content-Type: application/x-www-form-urlencoded\nContent-Length: 8\n";

    #[test]
    fn only_a_post_from_the_own_page_is_a_state_change() {
        let own = head(&format!(
            "POST /join HTTP/1.1\nHost: 127.0.0.1:8080\nOrigin: http://127.0.0.1:8080\n\
             Sec-Fetch-Site: same-origin\n{FORM}\n"
        ));
        assert_eq!(check_own_post(&own), Ok(()));
        assert_eq!(form_length(&own), Ok(8));
        // A link another site's page makes the browser follow.
        let link = head(
            "GET /join?name=Eve HTTP/1.1\nHost: 127.0.0.1:8080\nSec-Fetch-Site: cross-site\n\n",
        );
        let e = check_own_post(&link).unwrap_err();
        assert_eq!(
            e.to_string(),
            "GET /join changes state: send it as POST from this server's own page"
        );
        assert_eq!(e.status(), "405 Method Not Allowed");
        // A POST without Origin (not a browser's form), and one from another site.
        let bare = head(&format!(
            "POST /join HTTP/1.1\nHost: 127.0.0.1:8080\n{FORM}\n"
        ));
        assert_eq!(check_own_post(&bare), Err(FormError::NoOrigin));
        assert_eq!(FormError::NoOrigin.kind(), "origin");
        for site in ["cross-site", "same-site", "none"] {
            let h = head(&format!(
                "POST /join HTTP/1.1\nHost: 127.0.0.1:8080\nOrigin: http://127.0.0.1:8080\n\
                 Sec-Fetch-Site: {site}\n{FORM}\n"
            ));
            let e = check_own_post(&h).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!(
                    "Sec-Fetch-Site `{site}` is refused: allowed `same-origin` (a request from \
                     another site may not change this server's state)"
                )
            );
            assert_eq!((e.kind(), e.status()), ("origin", "403 Forbidden"));
        }
    }

    #[test]
    fn a_form_body_is_bounded_and_typed() {
        let with = |extra: &str| {
            form_length(&head(&format!(
                "POST /join HTTP/1.1\nHost: 127.0.0.1:8080\nOrigin: http://127.0.0.1:8080\n{extra}\n"
            )))
        };
        assert_eq!(
            with(
                "Content-Type: application/x-www-form-urlencoded; charset=UTF-8\nContent-Length: 2048\n"
            ),
            Ok(2048)
        );
        let e = with("Content-Type: application/x-www-form-urlencoded\nContent-Length: 2049\n")
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "Content-Length `2049` is refused: allowed 0 to 2048 bytes"
        );
        assert_eq!((e.kind(), e.status()), ("size", "413 Content Too Large"));
        for bad in ["", "-1", "+5", "1e3", "99999999999999999999999"] {
            let h = if bad.is_empty() {
                String::from("Content-Type: application/x-www-form-urlencoded\n")
            } else {
                format!("Content-Type: application/x-www-form-urlencoded\nContent-Length: {bad}\n")
            };
            assert_eq!(
                with(&h).unwrap_err(),
                FormError::Length {
                    got: bad.to_string(),
                    limit: MAX_FORM_BYTES
                },
                "{bad}"
            );
        }
        let e = with("Content-Type: text/plain\nContent-Length: 2\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "Content-Type `text/plain` is refused: allowed `application/x-www-form-urlencoded` \
             (an HTML form)"
        );
        assert_eq!(e.status(), "415 Unsupported Media Type");
    }

    #[test]
    fn a_form_is_decoded_field_by_field() {
        let f = Form::parse("name=Ada+L%C3%B6w&code=123456&empty=&bare").unwrap();
        assert_eq!(f.get("name"), Some("Ada Löw"));
        assert_eq!(f.get("code"), Some("123456"));
        assert_eq!(f.get("empty"), Some(""));
        assert_eq!(f.get("bare"), Some(""));
        assert_eq!(f.get("x"), None);
        assert_eq!(Form::parse("name=%ZZ"), None);
        assert_eq!(Form::parse("name=%FF"), None);
        assert_eq!(Form::parse(""), Some(Form::default()));
    }
}
