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
        // An HTML block (the line starts with a tag) and a paragraph with
        // inline HTML and a Markdown link.
        for text in [
            "<script>alert(1)</script> <img src=x onerror=alert(2)> \
             <a href=\"JaVaScRiPt:alert(4)\">y</a> <iframe src=\"https://evil\"></iframe>",
            "See [x](javascript:alert(3)) and <b onclick=\"alert(5)\">this</b><script>alert(1)</script>",
        ] {
            let html = render(text);
            let lower = html.to_ascii_lowercase();
            for bad in ["<script", "onerror", "onclick", "href=\"javascript", "<iframe", "alert(1)"] {
                assert!(!lower.contains(bad), "{bad} survived in {html}");
            }
        }
        assert_eq!(
            render("See [x](javascript:alert(3))"),
            "<p>See <a rel=\"noopener noreferrer nofollow\">x</a></p>\n"
        );
    }
}
