//! Annotation text: Markdown rendered by pulldown-cmark, then sanitised by
//! ammonia, so no raw HTML, script, event handler or `javascript:` URL ever
//! reaches the page. Links get `rel="noopener noreferrer nofollow"`.

use pulldown_cmark::{html, Options, Parser};

/// The sanitised HTML of `text`.
pub fn render(text: &str) -> String {
    let parser = Parser::new_ext(text, Options::ENABLE_STRIKETHROUGH | Options::ENABLE_TABLES);
    let mut unsafe_html = String::with_capacity(text.len() * 3 / 2);
    html::push_html(&mut unsafe_html, parser);
    ammonia::Builder::default()
        .url_schemes(["http", "https", "mailto"].into())
        .link_rel(Some("noopener noreferrer nofollow"))
        .clean(&unsafe_html)
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::render;

    #[test]
    fn markdown_is_rendered() {
        assert_eq!(
            render("A *carved* [mark](https://example.org)"),
            "<p>A <em>carved</em> <a href=\"https://example.org\" rel=\"noopener noreferrer nofollow\">mark</a></p>\n"
        );
    }

    #[test]
    fn scripts_and_javascript_urls_are_removed() {
        let html = render(
            "<script>alert(1)</script> <img src=x onerror=alert(2)> [x](javascript:alert(3)) \
             <a href=\"JaVaScRiPt:alert(4)\">y</a> <iframe src=\"https://evil\"></iframe>",
        );
        let lower = html.to_ascii_lowercase();
        for bad in ["<script", "onerror", "javascript:", "<iframe", "alert(1)"] {
            assert!(!lower.contains(bad), "{bad} survived in {html}");
        }
    }
}
