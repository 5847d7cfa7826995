//! The option tables as users see them (README "Options"): `penumbra list --options` is
//! generated from the tables' declarations, README reproduces it exactly (so the two cannot
//! drift), README spells no key in snake case, `render --help` points to the listing, and the
//! default the listing prints for every key reads back as that default.

use penumbra::frame::GpuOptions;
use penumbra::methods::raycast::RaycastOptions;
use penumbra::methods::{self, dbuffer, hard_sv, nsample, penumbra_map, pw2002, pw_restructured};
use penumbra::methods::{ssv, ssv_optimized, wedge_blending};
use penumbra::options::{listing, DefaultValue, OptionTable};
use penumbra::scene::{builtin, OptionValue};
use std::collections::BTreeSet;
use std::fmt::Debug;
use std::path::Path;
use std::process::Command;

/// `penumbra ARGS`' stdout, which must succeed.
fn penumbra(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .output()
        .expect("cannot run the penumbra binary");
    assert_eq!(out.status.code(), Some(0), "penumbra {args:?}: {out:?}");
    String::from_utf8(out.stdout).expect("UTF-8")
}

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md"))
        .expect("README.md")
}

/// The first fenced block after the heading `### Options` of README.
fn readme_listing() -> String {
    let text = readme();
    let section = text
        .split_once("\n### Options\n")
        .expect("README has a section \"### Options\"")
        .1;
    let block = section
        .split_once("```text\n")
        .expect("a ```text block in README \"Options\"")
        .1;
    block
        .split_once("```")
        .expect("the block is closed")
        .0
        .to_string()
}

/// The (table, key) pairs a listing names: `[options.TABLE]` headers and `  KEY = …` lines.
fn keys_of(listing: &str) -> BTreeSet<(String, String)> {
    let mut table = String::new();
    let mut keys = BTreeSet::new();
    for line in listing.lines() {
        if let Some(name) = line.strip_prefix("[options.") {
            table = name.trim_end_matches(']').to_string();
        } else if let Some((key, _)) = line.strip_prefix("  ").and_then(|l| l.split_once(" = ")) {
            if !key.starts_with(' ') {
                keys.insert((table.clone(), key.to_string()));
            }
        }
    }
    keys
}

#[test]
fn readme_lists_exactly_the_keys_the_program_lists() {
    let printed = penumbra(&["list", "--options"]);
    assert_eq!(printed, listing(&methods::option_docs()));
    let documented = readme_listing();
    let (code, readme) = (keys_of(&printed), keys_of(&documented));
    let missing: Vec<_> = code.difference(&readme).collect();
    let stale: Vec<_> = readme.difference(&code).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "README \"Options\" lacks {missing:?} and names keys that do not exist: {stale:?}"
    );
    // Every table, every key: at least one key per table and the tables the registry has.
    let tables: BTreeSet<&str> = code.iter().map(|(t, _)| t.as_str()).collect();
    let expected: BTreeSet<&str> = ["gpu"].into_iter().chain(methods::names()).collect();
    assert_eq!(tables, expected);
    assert_eq!(
        documented, printed,
        "README \"Options\" is not the output of `penumbra list --options`: paste it"
    );
}

#[test]
fn keys_are_kebab_case_unique_and_documented() {
    for (table, keys) in methods::option_docs() {
        let mut seen = BTreeSet::new();
        for k in &keys {
            assert!(
                !k.key.is_empty()
                    && k.key
                        .chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
                "[options.{table}] {}: not kebab-case",
                k.key
            );
            assert!(seen.insert(&k.key), "[options.{table}] {} twice", k.key);
            assert!(
                !k.meaning.is_empty(),
                "[options.{table}] {}: no meaning",
                k.key
            );
            let (DefaultValue::Written(d) | DefaultValue::FromScene(d)) = &k.default;
            assert!(!d.is_empty(), "[options.{table}] {}: no default", k.key);
        }
    }
}

#[test]
fn readme_spells_no_key_in_snake_case() {
    let text = readme();
    for (table, keys) in methods::option_docs() {
        for k in keys.iter().filter(|k| k.key.contains('-')) {
            let snake = k.key.replace('-', "_");
            for written in [
                format!("`{snake}`"),
                format!("{snake} ="),
                format!("{snake}="),
            ] {
                assert!(
                    !text.contains(&written),
                    "README writes {written:?}; [options.{table}] spells it {}",
                    k.key
                );
            }
        }
    }
}

#[test]
fn render_help_points_to_the_listing() {
    let help = penumbra(&["render", "--help"]);
    assert!(help.contains("penumbra list --options"), "{help}");
}

/// Every printed default of table `O`, set as the scene file writes it (a string) and as
/// `--opt` does, reads back as the default; returns the table's name.
fn printed_defaults_read_back<O: OptionTable + PartialEq + Debug>() -> &'static str {
    for key in O::keys() {
        let DefaultValue::Written(text) = &key.default else {
            continue;
        };
        for value in [OptionValue::Str(text.clone()), OptionValue::parse_cli(text)] {
            let mut scene = builtin::load("single-quad").unwrap();
            scene
                .options
                .entry(O::NAME.into())
                .or_default()
                .insert(key.key.clone(), value.clone());
            let read = O::read(&scene).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                read,
                O::default(),
                "[options.{}] {} = {value}",
                O::NAME,
                key.key
            );
        }
    }
    O::NAME
}

#[test]
fn every_printed_default_reads_back_as_the_default() {
    let checked = [
        printed_defaults_read_back::<GpuOptions>(),
        printed_defaults_read_back::<RaycastOptions>(),
        printed_defaults_read_back::<nsample::NsampleOptions>(),
        printed_defaults_read_back::<hard_sv::HardSvOptions>(),
        printed_defaults_read_back::<pw2002::Pw2002Options>(),
        printed_defaults_read_back::<pw_restructured::PwRestructuredOptions>(),
        printed_defaults_read_back::<ssv_optimized::SsvOptimizedOptions>(),
        printed_defaults_read_back::<ssv::SsvOptions>(),
        printed_defaults_read_back::<wedge_blending::WedgeBlendingOptions>(),
        printed_defaults_read_back::<penumbra_map::PenumbraMapOptions>(),
        printed_defaults_read_back::<dbuffer::DBufferOptions>(),
    ];
    let all: Vec<&str> = methods::option_docs().iter().map(|(n, _)| *n).collect();
    assert_eq!(checked.to_vec(), all, "a table is not checked here");
}
