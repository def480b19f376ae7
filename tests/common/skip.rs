//! What a test does when its data or tool is missing: outside CI it skips with a loud
//! warning; in CI (`CI=true`) it fails, since CI must run everything.

/// Skips (returns) loudly, or panics under `CI=true`, naming `what` is missing: "need: detail",
/// the summary of `scripts/test-all.sh` counting skips by the need before the colon.
pub fn skip_or_fail(what: &str) {
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("CI=true but {what}: the test cannot run");
    }
    // Straight to the stderr handle: libtest captures eprintln! of passing tests.
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "\n!!! {what}: this test is SKIPPED\n");
}
