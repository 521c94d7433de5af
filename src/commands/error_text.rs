//! What `fovea` prints when a command fails: the error's message and its causes', joined as
//! anyhow's `{:#}` joins them, except that a cause the text before it already says is left
//! out. A thiserror message that writes its own `source` (`cannot read '{path}': {source}`)
//! would otherwise print the cause twice.

/// The error's message, then each cause not already said, joined by ": ".
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let said = cause.to_string();
        if text.contains(&said) {
            continue;
        }
        if !text.is_empty() {
            text += ": ";
        }
        text += &said;
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("cannot read '{path}': {source}")]
    struct ReadFailed {
        path: String,
        source: std::io::Error,
    }

    #[test]
    fn a_cause_the_message_already_says_is_said_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::from(ReadFailed {
            path: "a.txt".into(),
            source: io,
        });
        assert_eq!(
            format!("{e:#}"),
            "cannot read 'a.txt': no such file: no such file"
        );
        assert_eq!(error_text(&e), "cannot read 'a.txt': no such file");
    }

    #[test]
    fn causes_the_message_does_not_say_are_kept_in_order() {
        let e = anyhow::anyhow!("no such file")
            .context("reading a.txt")
            .context("loading the scene");
        assert_eq!(
            error_text(&e),
            "loading the scene: reading a.txt: no such file"
        );
    }
}
