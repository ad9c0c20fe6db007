//! The arguments Windows hands a screen saver, as Windows spells them: the
//! mode letter after `/` or `-`, in either case, and the window's handle
//! after a colon or as the next argument (`/p 1234`, `/p:1234`, `/P 1234`).

/// What Windows asks of the screen saver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// `/s`: full screen until a key press, a click or a mouse move.
    Saver,
    /// `/p HWND`: the small preview in the control panel, drawn into the
    /// window it hands (by its handle).
    Preview(usize),
    /// `/c`, `/c:HWND` (the settings dialog's owner), or no argument at
    /// all (what the "Settings" button and a double click send).
    Configure(Option<usize>),
}

/// Reads the arguments after the program's name.
pub fn parse(args: &[String]) -> Result<Mode, String> {
    let Some(first) = args.first() else {
        return Ok(Mode::Configure(None));
    };
    let flag = first
        .strip_prefix('/')
        .or_else(|| first.strip_prefix('-'))
        .ok_or_else(|| format!("unknown argument `{first}`: expected /s, /p HWND or /c"))?;
    let (letter, attached) = match flag.split_once(':') {
        Some((letter, handle)) => (letter, Some(handle)),
        None => (flag, None),
    };
    let handle = || -> Result<Option<usize>, String> {
        let text = match (attached, args.get(1)) {
            (Some(text), _) => text,
            (None, Some(text)) => text.as_str(),
            (None, None) => return Ok(None),
        };
        parse_handle(text).map(Some)
    };
    match letter.to_ascii_lowercase().as_str() {
        "s" => Ok(Mode::Saver),
        "p" => match handle()? {
            Some(hwnd) => Ok(Mode::Preview(hwnd)),
            None => Err(format!("`{first}` needs the preview window's handle")),
        },
        "c" => Ok(Mode::Configure(handle()?)),
        _ => Err(format!(
            "unknown argument `{first}`: expected /s, /p HWND or /c"
        )),
    }
}

/// A window handle as Windows writes it in the arguments: a decimal
/// number (also taken in hexadecimal with `0x`, as people type it).
fn parse_handle(text: &str) -> Result<usize, String> {
    let parsed = match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) => usize::from_str_radix(hex, 16),
        None => text.parse::<usize>(),
    };
    match parsed {
        Ok(0) | Err(_) => Err(format!("`{text}` is not a window handle")),
        Ok(hwnd) => Ok(hwnd),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(args: &[&str]) -> Result<Mode, String> {
        parse(&args.iter().map(|a| a.to_string()).collect::<Vec<_>>())
    }

    #[test]
    fn windows_spellings() {
        for s in ["/s", "/S", "-s", "-S"] {
            assert_eq!(parsed(&[s]), Ok(Mode::Saver), "{s}");
        }
        for p in [
            &["/p", "1234"][..],
            &["/P", "1234"],
            &["/p:1234"],
            &["-p", "1234"],
        ] {
            assert_eq!(parsed(p), Ok(Mode::Preview(1234)), "{p:?}");
        }
        assert_eq!(parsed(&["/p", "0x4d2"]), Ok(Mode::Preview(1234)));
        assert_eq!(parsed(&[]), Ok(Mode::Configure(None)));
        assert_eq!(parsed(&["/c"]), Ok(Mode::Configure(None)));
        assert_eq!(parsed(&["/C:5678"]), Ok(Mode::Configure(Some(5678))));
        assert_eq!(parsed(&["-c", "5678"]), Ok(Mode::Configure(Some(5678))));
    }

    #[test]
    fn refusals() {
        assert!(parsed(&["/p"]).is_err());
        assert!(parsed(&["/p:0"]).is_err());
        assert!(parsed(&["/p", "window"]).is_err());
        assert!(parsed(&["/x"]).is_err());
        assert!(parsed(&["s"]).is_err());
        assert!(parsed(&["/c:nope"]).is_err());
    }
}
