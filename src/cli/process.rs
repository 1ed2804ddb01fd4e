//! What the process needs before any command runs: a runtime directory for software
//! Vulkan, and the quiet end of a Unix filter on a closed pipe.

use std::path::Path;

/// Software Vulkan (lavapipe) prints an error on every start without a runtime directory;
/// give it a private one when the environment has none.
pub fn ensure_runtime_dir() {
    let usable = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir());
    if usable {
        return;
    }
    let dir = std::env::temp_dir().join("tactex-xdg-runtime");
    if std::fs::create_dir_all(&dir).is_ok() {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
        }
        // SAFETY: called first thing in main, before any thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

/// A closed stdout (`tactex ask ... | head -1`) ends the program quietly, as it does any Unix
/// filter, instead of println! panicking on the broken pipe. Not for `serve`: a browser
/// that goes away must not end the server.
pub fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; restores the default.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// A stdout that cannot be written (a full disk, `> /dev/full`) ends the program with one
/// error line and a failure exit, as any output that cannot be written does, rather than
/// with println!'s panic and backtrace.
pub fn one_line_on_stdout_failure() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if let Some(why) = message.strip_prefix("failed printing to stdout: ") {
            eprintln!("error: stdout: cannot write the output: {why}");
            std::process::exit(1);
        }
        default(info);
    }));
}
