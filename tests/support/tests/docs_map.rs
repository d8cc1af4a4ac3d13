//! The repository's maps of itself agree with the repository.
//!
//! `ARCHITECTURE.md`, `TESTING.md` and the design pages in `docs/design/`
//! point at files and name types and functions so that a reader can grep
//! for them; this test keeps them honest:
//!
//! 1. every path they name — in backticks, or as a link — exists, and every
//!    link to a heading finds that heading;
//! 2. every name in backticks that looks like a Rust item (`Type`,
//!    `Type::method`, `snake_case_fn`, `CONST_NAME`) is found, as a whole
//!    word, in the files its paragraph (list item, table row) names — or,
//!    if it names none, the files its section names (then the page's, then
//!    the repository's sources);
//! 3. every section number cited anywhere in the repository — a `§` number
//!    after the word SPEC, SPEC.md or docs/design, or a bare one in these
//!    pages — has a row in `docs/design/README.md`'s table, and every row's
//!    link finds its page and heading.
//!
//! It reads a few hundred text files and builds nothing of the workspace:
//! it lives in `test_support`, which has no dependencies, so
//! `cargo test -p test_support --test docs_map` runs in seconds.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use test_support::repo::root;

/// The map pages at the repository's root.
const MAPS: [&str; 2] = ["ARCHITECTURE.md", "TESTING.md"];
/// The design pages.
const DESIGN: &str = "docs/design";
/// The design pages' index, with the table of section numbers.
const DESIGN_INDEX: &str = "docs/design/README.md";
/// Files a citation or an item may be in.
const TEXT: [&str; 8] = ["rs", "md", "py", "toml", "service", "sh", "yml", "json"];

/// Directories never walked: build output, VCS data, local environments,
/// the Python tools' caches.
fn skipped_dir(name: &str) -> bool {
    matches!(
        name,
        "target"
            | ".git"
            | "node_modules"
            | "__pycache__"
            | ".mypy_cache"
            | ".ruff_cache"
            | ".pytest_cache"
    ) || name.starts_with(".venv")
}

/// Every text file under `dir` (relative to `root`), sorted.
fn text_files(root: &Path, dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = fs::read_dir(root.join(&d)) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let rel = d.join(&name);
            let Ok(kind) = e.file_type() else { continue };
            if kind.is_dir() {
                if !skipped_dir(&name) {
                    stack.push(rel);
                }
            } else if rel
                .extension()
                .is_some_and(|x| TEXT.contains(&x.to_string_lossy().as_ref()))
            {
                out.push(rel);
            }
        }
    }
    out.sort();
    out
}

/// The pages this test checks: the map pages and every design page.
fn pages(root: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = MAPS.iter().map(PathBuf::from).collect();
    let mut design: Vec<PathBuf> = fs::read_dir(root.join(DESIGN))
        .expect("docs/design exists")
        .flatten()
        .map(|e| Path::new(DESIGN).join(e.file_name()))
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    design.sort();
    out.extend(design);
    out
}

/// A paragraph, list item or table row, with the heading it is under.
struct Block {
    /// 1-based line of its first line.
    line: usize,
    text: String,
    /// Index into the page's headings, if under one.
    section: Option<usize>,
}

struct Heading {
    level: usize,
    text: String,
}

struct Page {
    path: PathBuf,
    blocks: Vec<Block>,
    headings: Vec<Heading>,
}

fn starts_item(line: &str) -> bool {
    let t = line.trim_start();
    if t.starts_with("- ") || t.starts_with("* ") || t.starts_with('|') {
        return true;
    }
    let digits = t.chars().take_while(char::is_ascii_digit).count();
    digits > 0 && t[digits..].starts_with(". ")
}

/// Splits Markdown into blocks and headings; fenced code is left out.
fn parse(path: &Path, text: &str) -> Page {
    let mut page = Page {
        path: path.to_path_buf(),
        blocks: Vec::new(),
        headings: Vec::new(),
    };
    let mut fenced = false;
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            page.blocks.extend(open.take());
            continue;
        }
        if fenced {
            continue;
        }
        if line.starts_with('#') {
            page.blocks.extend(open.take());
            let level = line.chars().take_while(|&c| c == '#').count();
            page.headings.push(Heading {
                level,
                text: line[level..].trim().to_string(),
            });
            continue;
        }
        if line.trim().is_empty() {
            page.blocks.extend(open.take());
            continue;
        }
        if starts_item(line) {
            page.blocks.extend(open.take());
        }
        match open.as_mut() {
            Some(b) => {
                b.text.push(' ');
                b.text.push_str(line.trim());
            }
            None => {
                open = Some(Block {
                    line: i + 1,
                    text: line.trim().to_string(),
                    section: page.headings.len().checked_sub(1),
                })
            }
        }
    }
    page.blocks.extend(open);
    page
}

/// GitHub's anchor for a heading: lower case, spaces to hyphens, other
/// punctuation (backticks, dots, apostrophes, dashes other than `-`) dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            '-' | '_' => Some(c),
            c if c.is_alphanumeric() => Some(c),
            _ => None,
        })
        .collect()
}

/// The inline code spans of a block.
fn code_spans(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(a) = rest.find('`') {
        let after = &rest[a + 1..];
        let Some(b) = after.find('`') else { break };
        out.push(&after[..b]);
        rest = &after[b + 1..];
    }
    out
}

/// The targets of the Markdown links `[text](target)` of a block.
fn link_targets(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(a) = rest.find("](") {
        let after = &rest[a + 2..];
        let Some(b) = after.find(')') else { break };
        out.push(after[..b].trim());
        rest = &after[b + 1..];
    }
    out
}

/// The repository's top-level entries (what a path in a page starts with).
fn top_entries(root: &Path) -> BTreeSet<String> {
    fs::read_dir(root)
        .expect("repository root")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !skipped_dir(n))
        .collect()
}

enum Token<'a> {
    /// A repository path (relative to the root).
    Path(&'a str),
    /// Looks like a path to a source file but does not start at the root.
    NotFromRoot(&'a str),
    /// A Rust item: its `::` segments.
    Item(Vec<&'a str>),
    Other,
}

fn is_ident(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

fn classify<'a>(span: &'a str, tops: &BTreeSet<String>) -> Token<'a> {
    let t = span.trim();
    if t.is_empty() || t.contains(char::is_whitespace) {
        return Token::Other;
    }
    let first = t.split('/').next().unwrap_or("");
    let pathish = !t.contains(['*', '<', '>', '{', '}', '$', '=', '|', '#']);
    if pathish && tops.contains(first) {
        return Token::Path(t);
    }
    let source_ext = [".rs", ".md", ".toml", ".py", ".sh", ".service"];
    if pathish
        && t.contains('/')
        && !t.starts_with(['/', '~', '.'])
        && source_ext.iter().any(|x| t.ends_with(x))
    {
        return Token::NotFromRoot(t);
    }
    let name = t.strip_suffix("()").unwrap_or(t);
    let segments: Vec<&str> = name.split("::").collect();
    if !segments.iter().all(|s| is_ident(s)) {
        return Token::Other;
    }
    let camel = name.starts_with(|c: char| c.is_ascii_uppercase())
        && name.contains(|c: char| c.is_ascii_lowercase());
    if segments.len() > 1 || camel || name.contains('_') {
        Token::Item(segments)
    } else {
        Token::Other
    }
}

/// Whether `word` occurs in `text` with no identifier character either side.
fn has_word(text: &str, word: &str) -> bool {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.match_indices(word).any(|(i, _)| {
        !text[..i].chars().next_back().is_some_and(ident)
            && !text[i + word.len()..].chars().next().is_some_and(ident)
    })
}

/// Reads files once.
struct Files {
    root: PathBuf,
    cache: BTreeMap<PathBuf, String>,
    sources: Vec<PathBuf>,
}

impl Files {
    fn text(&mut self, rel: &Path) -> &str {
        let root = &self.root;
        self.cache
            .entry(rel.to_path_buf())
            .or_insert_with(|| fs::read_to_string(root.join(rel)).unwrap_or_default())
    }

    /// The text files a path stands for: itself, or every one under it.
    fn expand(&self, rel: &Path) -> Vec<PathBuf> {
        if self.root.join(rel).is_dir() {
            text_files(&self.root, rel)
        } else {
            vec![rel.to_path_buf()]
        }
    }

    /// Whether every segment of `item` is a word of one of `files`.
    fn found(&mut self, item: &[&str], files: &[PathBuf]) -> bool {
        for f in files {
            self.text(f);
        }
        item.iter()
            .all(|seg| files.iter().any(|f| has_word(&self.cache[f], seg)))
    }
}

/// Checks 1 and 2 on one page; returns the problems found.
fn check_page(files: &mut Files, tops: &BTreeSet<String>, page: &Page) -> Vec<String> {
    let root = files.root.clone();
    let mut problems = Vec::new();
    let where_ = |b: &Block| format!("{}:{}", page.path.display(), b.line);
    // The existing paths each block names.
    let mut named: Vec<Vec<PathBuf>> = Vec::new();
    for b in &page.blocks {
        let mut paths = Vec::new();
        for span in code_spans(&b.text) {
            match classify(span, tops) {
                Token::Path(p) => {
                    if root.join(p).exists() {
                        paths.push(PathBuf::from(p));
                    } else {
                        problems.push(format!("{}: `{p}` does not exist", where_(b)));
                    }
                }
                Token::NotFromRoot(p) => problems.push(format!(
                    "{}: `{p}` is not a path from the repository's root",
                    where_(b)
                )),
                _ => {}
            }
        }
        for target in link_targets(&b.text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (file, anchor) = target.split_once('#').unwrap_or((target, ""));
            let dir = page.path.parent().unwrap_or(Path::new(""));
            let rel = if file.is_empty() {
                Some(page.path.clone())
            } else {
                normalise(&dir.join(file))
            };
            let Some(rel) = rel else {
                problems.push(format!(
                    "{}: link `{target}` leaves the repository",
                    where_(b)
                ));
                continue;
            };
            if !root.join(&rel).exists() {
                problems.push(format!("{}: link `{target}` finds no file", where_(b)));
                continue;
            }
            if !anchor.is_empty() && rel.extension().is_some_and(|x| x == "md") {
                let text = files.text(&rel).to_string();
                let anchors: BTreeSet<String> = parse(&rel, &text)
                    .headings
                    .iter()
                    .map(|h| slug(&h.text))
                    .collect();
                if !anchors.contains(anchor) {
                    problems.push(format!(
                        "{}: link `{target}`: no heading with anchor #{anchor} in {}",
                        where_(b),
                        rel.display()
                    ));
                }
            }
            paths.push(rel);
        }
        named.push(paths);
    }
    // The paths of each section: its own blocks' and its ancestors'.
    let section_paths = |s: Option<usize>| -> Vec<PathBuf> {
        let mut out = Vec::new();
        let mut want = s;
        let mut level = usize::MAX;
        while let Some(h) = want {
            if page.headings[h].level < level {
                level = page.headings[h].level;
                for (b, paths) in page.blocks.iter().zip(&named) {
                    if b.section == Some(h) {
                        out.extend(paths.iter().cloned());
                    }
                }
            }
            want = h.checked_sub(1);
        }
        out
    };
    let page_paths: Vec<PathBuf> = named.iter().flatten().cloned().collect();
    for (b, paths) in page.blocks.iter().zip(&named) {
        for span in code_spans(&b.text) {
            let Token::Item(item) = classify(span, tops) else {
                continue;
            };
            let scopes = [paths.clone(), section_paths(b.section), page_paths.clone()];
            let scope = scopes.into_iter().find(|s| !s.is_empty());
            let (targets, said) = match scope {
                Some(s) => {
                    let said = s
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ");
                    (s.iter().flat_map(|p| files.expand(p)).collect(), said)
                }
                None => (
                    files.sources.clone(),
                    "the repository's sources".to_string(),
                ),
            };
            if !files.found(&item, &targets) {
                problems.push(format!("{}: `{span}` is not found in {said}", where_(b)));
            }
        }
    }
    problems
}

/// `a/b/../c` → `a/c`, relative to the root; `None` if it climbs out.
fn normalise(p: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            std::path::Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            std::path::Component::CurDir => {}
            c => out.push(c),
        }
    }
    Some(out)
}

/// A section number: digits, then `.digits` groups.
fn number_at(s: &str) -> Option<(String, usize)> {
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if i == 0 {
        return None;
    }
    while i + 1 < b.len() && b[i] == b'.' && b[i + 1].is_ascii_digit() {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
    }
    Some((s[..i].to_string(), i))
}

/// The word before byte `at` (letters, digits and `./_-'’`).
fn word_before(s: &str, at: usize) -> &str {
    let head = s[..at].trim_end();
    let start = head
        .char_indices()
        .rev()
        .take_while(|&(_, c)| c.is_alphanumeric() || "./_-'’".contains(c))
        .last()
        .map_or(head.len(), |(i, _)| i);
    &head[start..]
}

/// The section numbers cited in `text`: chains `§a, §b`, `§a/§b`, `§a–b`
/// whose first `§` follows a word `accept` takes.
fn citations(text: &str, accept: impl Fn(&str) -> bool) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(k) = text[from..].find('§') {
        let at = from + k;
        let word = word_before(text, at);
        let mut pos = at + '§'.len_utf8();
        let mut chain = Vec::new();
        let Some((n, len)) = number_at(&text[pos..]) else {
            from = pos;
            continue;
        };
        chain.push(n);
        pos += len;
        loop {
            let rest = &text[pos..];
            let trimmed = rest.trim_start();
            let skipped = rest.len() - trimmed.len();
            let (sep, range) = if let Some(r) = trimmed.strip_prefix('–') {
                (r, true)
            } else if let Some(r) = trimmed.strip_prefix('-') {
                (r, true)
            } else if let Some(r) = trimmed
                .strip_prefix(',')
                .or_else(|| trimmed.strip_prefix('/'))
                .or_else(|| trimmed.strip_prefix("and "))
                .or_else(|| trimmed.strip_prefix("or "))
            {
                (r, false)
            } else {
                break;
            };
            let after = sep.trim_start();
            let (after, marked) = match after.strip_prefix('§') {
                Some(a) => (a, true),
                None => (after, false),
            };
            if !(marked || range) {
                break;
            }
            let Some((n, len)) = number_at(after) else {
                break;
            };
            chain.push(n);
            pos += skipped + (trimmed.len() - after.len()) + len;
        }
        if accept(word) {
            let line = text[..at].matches('\n').count() + 1;
            out.extend(chain.into_iter().map(|n| (line, n)));
        }
        from = pos;
    }
    out
}

/// A citation of the design anywhere: after `SPEC`, `SPEC.md` or
/// `docs/design` (and `design`).
fn cites_design(word: &str) -> bool {
    let w = word.trim_matches(|c| c == '(' || c == '`');
    w.ends_with("SPEC") || w.ends_with("SPEC.md") || w.ends_with("design")
}

/// In the design and map pages a bare `§n` is the design's too, unless it
/// follows the paper or another document.
fn cites_design_here(word: &str) -> bool {
    let w = word.to_lowercase();
    let other = w.ends_with("paper")
        || w.ends_with("paper's")
        || w.ends_with("paper’s")
        || w.contains("figures")
        || (w.ends_with(".md") && !w.ends_with("spec.md"));
    cites_design(word) || !other
}

/// The section table of `docs/design/README.md`: number → link target.
fn section_table(text: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for line in text.lines() {
        let Some(row) = line.trim().strip_prefix('|') else {
            continue;
        };
        let first = row.split('|').next().unwrap_or("").trim();
        let Some((n, len)) = number_at(first) else {
            continue;
        };
        if len != first.len() {
            continue;
        }
        if let Some(target) = link_targets(row).first() {
            out.insert(n, target.to_string());
        }
    }
    out
}

#[test]
fn the_maps_name_files_and_items_that_exist() {
    let root = root();
    let tops = top_entries(&root);
    let sources = text_files(&root, Path::new(""))
        .into_iter()
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    let mut files = Files {
        root: root.clone(),
        cache: BTreeMap::new(),
        sources,
    };
    let mut problems = Vec::new();
    let mut checked = 0;
    for rel in pages(&root) {
        let text = fs::read_to_string(root.join(&rel))
            .unwrap_or_else(|e| panic!("{} cannot be read: {e}", rel.display()));
        let page = parse(&rel, &text);
        checked += page.blocks.len();
        problems.extend(check_page(&mut files, &tops, &page));
    }
    assert!(
        checked > 100,
        "only {checked} blocks found: the pages are missing"
    );
    assert!(
        problems.is_empty(),
        "{} problem(s) in the maps of the code:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn every_cited_section_has_a_heading() {
    let root = root();
    let index = fs::read_to_string(root.join(DESIGN_INDEX)).expect("docs/design/README.md");
    let table = section_table(&index);
    assert!(
        table.len() > 30,
        "the section table has {} rows",
        table.len()
    );
    let mut problems = Vec::new();
    // Every row's link finds its page and heading.
    for (n, target) in &table {
        let (file, anchor) = target.split_once('#').unwrap_or((target, ""));
        let rel = Path::new(DESIGN).join(file);
        let Ok(text) = fs::read_to_string(root.join(&rel)) else {
            problems.push(format!("§{n}: {} does not exist", rel.display()));
            continue;
        };
        let page = parse(&rel, &text);
        if !page.headings.iter().any(|h| slug(&h.text) == anchor) {
            problems.push(format!("§{n}: no heading #{anchor} in {}", rel.display()));
        }
        if !page
            .headings
            .iter()
            .any(|h| h.text.split_whitespace().next() == Some(n.as_str()))
        {
            problems.push(format!(
                "§{n}: no heading of {} starts with its number",
                rel.display()
            ));
        }
    }
    // Every number cited in the repository has a row.
    let ours: BTreeSet<PathBuf> = pages(&root).into_iter().collect();
    let mut cited = 0;
    for rel in text_files(&root, Path::new("")) {
        let Ok(text) = fs::read_to_string(root.join(&rel)) else {
            continue;
        };
        let found = if ours.contains(&rel) {
            citations(&text, cites_design_here)
        } else {
            citations(&text, cites_design)
        };
        for (line, n) in found {
            cited += 1;
            if !table.contains_key(&n) {
                problems.push(format!(
                    "{}:{line}: §{n} is cited but has no row in {DESIGN_INDEX}",
                    rel.display()
                ));
            }
        }
    }
    assert!(
        cited > 100,
        "only {cited} citations found: is the scan broken?"
    );
    assert!(
        problems.is_empty(),
        "{} problem(s) with section numbers:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn the_parsers_read_what_the_pages_write() {
    assert_eq!(slug("4.3 Required behaviour"), "43-required-behaviour");
    assert_eq!(slug("2.2 Montana's equations"), "22-montanas-equations");
    assert_eq!(
        slug("10 Trace format `gait-trajectory/1`"),
        "10-trace-format-gait-trajectory1"
    );
    let c = citations(
        "docs/design §2.2–2.3 and design §6.3, §6.4; docs/design §7.3/§12. \
         LOAD-FIGURES §10, §14; (docs/design §4.3, 5 % of) paper §2.1",
        cites_design,
    );
    let numbers: Vec<&str> = c.iter().map(|(_, n)| n.as_str()).collect();
    assert_eq!(numbers, ["2.2", "2.3", "6.3", "6.4", "7.3", "12", "4.3"]);
    // (The older form, spelt apart so that a search for it finds only
    // real citations.)
    assert!(cites_design("SPEC") && cites_design("(SPEC.md") && !cites_design("FIGURES"));
    let here = citations(
        "in §6.2, the paper's §5 and paper §3.1, §3.2",
        cites_design_here,
    );
    let numbers: Vec<&str> = here.iter().map(|(_, n)| n.as_str()).collect();
    assert_eq!(numbers, ["6.2"]);
    let tops: BTreeSet<String> = ["gait".to_string(), "README.md".to_string()].into();
    assert!(matches!(classify("gait/src/lib.rs", &tops), Token::Path(_)));
    assert!(matches!(
        classify("gaitd/schema.py", &tops),
        Token::NotFromRoot(_)
    ));
    assert!(matches!(classify("gaitd/status", &tops), Token::Other));
    assert!(matches!(classify("Executor::tick", &tops), Token::Item(s) if s.len() == 2));
    assert!(matches!(classify("plan_roll()", &tops), Token::Item(_)));
    assert!(matches!(classify("status", &tops), Token::Other));
    assert!(has_word("fn tick(&mut self)", "tick"));
    assert!(!has_word("fn ticker()", "tick"));
}
