//! The documentation stays true to the program: the CLI reference is the real `--help`, and every
//! relative link of the README and `docs/` reaches a file.

use std::path::{Path, PathBuf};

/// The committed CLI reference, relative to the project root.
const CLI_REFERENCE: &str = "docs/cli-reference.md";

fn project_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `docs/cli-reference.md` as generated from the clap definition of the command line.
///
/// The `Cli` type is the same with and without the `gui` feature (`eotn open` parses its options
/// in both builds and says the app is missing when it is), so the reference is one file and the
/// check runs in both builds.
fn generated_cli_reference() -> String {
    let body = clap_markdown::help_markdown::<eotn::cli::Cli>();
    format!(
        "<!-- Generated from `eotn --help` by tests/it/docs.rs; do not edit. Regenerate with\n     \
         UPDATE_CLI_REFERENCE=1 cargo test --test it cli_reference -->\n\n{body}"
    )
}

#[test]
fn cli_reference_is_current() {
    let path = project_root().join(CLI_REFERENCE);
    let want = generated_cli_reference();
    if std::env::var_os("UPDATE_CLI_REFERENCE").is_some() {
        std::fs::write(&path, &want).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have != want {
        let line = have
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| have.lines().count().min(want.lines().count()));
        panic!(
            "{CLI_REFERENCE} is not what `eotn --help` says (first difference at line {}).\n\
             Regenerate it and commit the result:\n    \
             UPDATE_CLI_REFERENCE=1 cargo test --test it cli_reference",
            line + 1
        );
    }
}

/// The targets of the Markdown links `[text](target)` in `text` that are not web addresses.
fn relative_link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut in_code_block = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code_block = !in_code_block;
        }
        if in_code_block {
            continue;
        }
        // Inline code (`[a](b)` shown as text) is every second piece between backticks.
        let prose: String = line.split('`').step_by(2).collect::<Vec<_>>().join(" ");
        let mut rest = prose.as_str();
        while let Some(start) = rest.find("](") {
            rest = &rest[start + 2..];
            let Some(end) = rest.find(')') else { break };
            let target = &rest[..end];
            rest = &rest[end..];
            let is_web = target.contains("://") || target.starts_with("mailto:");
            if !is_web && !target.is_empty() {
                targets.push(target.to_owned());
            }
        }
    }
    targets
}

/// GitHub's anchor for a heading: lower case, spaces to dashes, punctuation but `-`/`_` dropped.
fn heading_anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown file's headings (outside code blocks).
fn anchors(text: &str) -> Vec<String> {
    let mut in_code_block = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code_block = !in_code_block;
        }
        if !in_code_block && line.starts_with('#') {
            out.push(heading_anchor(line.trim_start_matches('#')));
        }
    }
    out
}

#[test]
fn relative_links_in_readme_and_docs_reach_a_file_and_heading() {
    let root = project_root();
    let mut pages: Vec<PathBuf> = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    assert!(pages.len() > 5, "README.md and the docs/ pages: {pages:?}");
    let mut broken = Vec::new();
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        let name = page.strip_prefix(root).unwrap_or(page).display();
        for target in relative_link_targets(&text) {
            let (file, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let file_path = if file.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(file)
            };
            if !file_path.exists() {
                broken.push(format!("{name}: {target} (no such file)"));
                continue;
            }
            let is_markdown = file_path.extension().is_some_and(|x| x == "md");
            if !anchor.is_empty() && is_markdown {
                let linked = std::fs::read_to_string(&file_path).unwrap();
                if !anchors(&linked).iter().any(|a| a == anchor) {
                    broken.push(format!("{name}: {target} (no such heading)"));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn link_and_anchor_helpers_read_markdown_as_github_does() {
    let text = "See [a](docs/a.md#the-app) and [web](https://x.org/y), `[b](c)`.\n\
                ```\n[in code](nowhere.md)\n```\n![shot](assets/s.png)";
    assert_eq!(
        relative_link_targets(text),
        ["docs/a.md#the-app", "assets/s.png"]
    );
    assert_eq!(
        heading_anchor(" Frames without sensor readings (measured 2026-12-03)"),
        "frames-without-sensor-readings-measured-2026-12-03"
    );
    assert_eq!(heading_anchor(" The app: `eotn open`"), "the-app-eotn-open");
}
