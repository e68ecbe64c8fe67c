//! The page's files, compiled into the binary: the viewer needs no network, no build step and no files beside
//! the program.

use axum::http::header;
use axum::response::{IntoResponse, Response};

/// One embedded file.
pub struct Asset {
    content_type: &'static str,
    text: &'static str,
}

impl Asset {
    /// The file as an HTTP response.
    pub fn respond(&self) -> Response {
        ([(header::CONTENT_TYPE, self.content_type)], self.text).into_response()
    }
}

/// `/`.
pub const INDEX: Asset = Asset {
    content_type: "text/html; charset=utf-8",
    text: include_str!("../page/index.html"),
};
/// `/viewer.js`.
pub const SCRIPT: Asset = Asset {
    content_type: "text/javascript; charset=utf-8",
    text: include_str!("../page/viewer.js"),
};
/// `/viewer.css`.
pub const STYLE: Asset = Asset {
    content_type: "text/css; charset=utf-8",
    text: include_str!("../page/viewer.css"),
};
