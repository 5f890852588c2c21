//! External estimator processes: started on demand, one per lane that
//! needs one, kept between requests, stopped on any fault of the protocol
//! (a process in an unknown state answers no more requests) and when the
//! run ends; and the watcher that stops them if lightquad itself is killed.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, sync_channel};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use super::protocol::{self, Hello, Request, Response};
use crate::family::Measured;

/// How far a program's own time for a request may exceed lightquad's
/// timing of it (the two clocks read at different moments), seconds.
const OWN_TIME_SLACK: f64 = 1e-3;

/// The stderr lines of a program kept for a failed job's message.
const STDERR_LINES: usize = 8;

/// The longest stderr line kept, characters.
const STDERR_LINE_CHARS: usize = 300;

/// The longest response line read: 1 MiB, and 64 bytes per channel above
/// that (a longer line fails the job instead of filling the memory).
fn longest_line(channels: usize) -> usize {
    (1 << 20) + 64 * channels
}

/// A program found and ready to start.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// The program file.
    pub path: PathBuf,
    /// Its arguments.
    pub args: Vec<String>,
    /// Its working folder: the experiment file's.
    pub folder: PathBuf,
}

/// One running program.
struct Server {
    child: Child,
    /// Lines for the thread that writes the program's stdin (a write that
    /// blocks, the program not reading, then never holds up the timeout).
    writer: SyncSender<String>,
    lines: Receiver<Result<String, String>>,
    limit: Arc<AtomicUsize>,
    stderr: Arc<Mutex<VecDeque<String>>>,
    requests: u64,
}

impl Server {
    /// Starts `program` and waits up to `timeout` for its [`Hello`].
    fn start(program: &Program, timeout: Duration) -> Result<Server, String> {
        use std::os::unix::process::CommandExt;
        // In a process group of its own, so that stopping it stops what it
        // started too (`sh -c` forks its command).
        let mut child = Command::new(&program.path)
            .args(&program.args)
            .current_dir(&program.folder)
            .process_group(0)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", program.path.display()))?;
        Watcher::get().watch(child.id());
        let (Some(stdin), Some(stdout), Some(stderr)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            let _ = child.kill();
            return Err("the program's pipes could not be opened".into());
        };
        let (writer, to_write) = sync_channel::<String>(1);
        std::thread::spawn(move || write_lines(stdin, &to_write));
        let limit = Arc::new(AtomicUsize::new(longest_line(1)));
        let (send, lines) = sync_channel(1);
        let cap = limit.clone();
        std::thread::spawn(move || read_lines(stdout, &cap, |l| send.send(l).is_ok()));
        let tail = Arc::new(Mutex::new(VecDeque::new()));
        let kept = tail.clone();
        std::thread::spawn(move || keep_tail(stderr, &kept));
        let mut server = Server {
            child,
            writer,
            lines,
            limit,
            stderr: tail,
            requests: 0,
        };
        server.hello(timeout).map_err(|why| {
            let tail = server
                .stderr_tail()
                .map(|t| format!("; its stderr ended: {t}"))
                .unwrap_or_default();
            format!("{why}{tail}")
        })?;
        Ok(server)
    }

    /// Reads the program's [`Hello`].
    fn hello(&mut self, timeout: Duration) -> Result<(), String> {
        let text = match self.lines.recv_timeout(timeout) {
            Ok(Ok(text)) => text,
            Ok(Err(why)) => return Err(why),
            Err(RecvTimeoutError::Timeout) => {
                return Err(format!(
                    "not ready within timeout_s = {} s (no hello line)",
                    timeout.as_secs_f64()
                ));
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(format!("no hello line{}", self.exited()));
            }
        };
        let hello: Hello = serde_json::from_str(&text).map_err(|e| {
            format!(
                "began with {:?}, which is not a hello line {{\"protocol\": \"{}\", \"version\": {}}} ({e})",
                crate::error::excerpt(&one_line(&text)),
                protocol::NAME,
                protocol::VERSION
            )
        })?;
        hello.mismatch().map_or(Ok(()), Err)
    }

    /// Sends `request` (its `id` set here) and waits up to `timeout` for the
    /// answer: the measured value and lightquad's own time for it, or why
    /// not, whether the process may serve again, and the seconds from
    /// sending the request to its failure (0 where it was not sent).
    fn ask(
        &mut self,
        mut request: Request,
        timeout: Duration,
    ) -> Result<(Measured, f64), (String, bool, f64)> {
        self.requests += 1;
        request.id = self.requests;
        self.limit
            .store(longest_line(request.channels), Ordering::Relaxed);
        let line = serde_json::to_string(&request).map_err(|e| (e.to_string(), false, 0.0))? + "\n";
        let start = Instant::now();
        let since = |start: Instant| start.elapsed().as_secs_f64();
        if self.writer.send(line).is_err() {
            let seconds = since(start);
            return Err((
                format!("could not send the request{}", self.exited()),
                false,
                seconds,
            ));
        }
        let text = match self.lines.recv_timeout(timeout) {
            Ok(Ok(text)) => text,
            Ok(Err(why)) => return Err((why, false, since(start))),
            Err(RecvTimeoutError::Timeout) => {
                return Err((
                    format!("no answer within timeout_s = {} s", timeout.as_secs_f64()),
                    false,
                    since(start),
                ));
            }
            Err(RecvTimeoutError::Disconnected) => {
                let seconds = since(start);
                return Err((format!("no answer{}", self.exited()), false, seconds));
            }
        };
        let seconds = since(start);
        let response: Response =
            serde_json::from_str(&text).map_err(|e| (garbage(&text, &e), false, seconds))?;
        let declined = response.error.is_some();
        protocol::answer(response, request.id, request.channels, request.budget)
            .map(|m| (m, seconds))
            .map_err(|e| (e, declined, seconds))
    }

    /// `: the program exited with <status>` when it has (waited for a moment).
    fn exited(&mut self) -> String {
        for _ in 0..20 {
            if let Ok(Some(status)) = self.child.try_wait() {
                return format!(": the program exited ({status})");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        String::new()
    }

    /// The last lines the program wrote to stderr, if any.
    fn stderr_tail(&self) -> Option<String> {
        let tail = self.stderr.lock().ok()?;
        (!tail.is_empty()).then(|| tail.iter().cloned().collect::<Vec<_>>().join(" | "))
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        kill_group(self.child.id());
        let _ = self.child.kill();
        let _ = self.child.wait();
        Watcher::get().forget(self.child.id());
    }
}

/// Sends SIGKILL to process group `pgid` (the program and what it started).
fn kill_group(pgid: u32) {
    let _ = Command::new("kill")
        .args(["-9", "--", &format!("-{pgid}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
}

/// Writes each line of `lines` to the program's stdin until the channel
/// closes (the server is dropped) or a write fails (the program is gone).
fn write_lines(mut stdin: ChildStdin, lines: &Receiver<String>) {
    for line in lines {
        if stdin
            .write_all(line.as_bytes())
            .and_then(|()| stdin.flush())
            .is_err()
        {
            return;
        }
    }
}

/// `text` from a program on one line of a report: line breaks and tabs as
/// spaces, other control characters as U+FFFD.
pub fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '\n' | '\r' | '\t' => ' ',
            c if c.is_control() => '\u{fffd}',
            c => c,
        })
        .collect()
}

/// Why a line is not a response, with the line's start.
fn garbage(text: &str, e: &serde_json::Error) -> String {
    let hint = if text.contains("NaN") || text.contains("Infinity") {
        " (JSON has no NaN or Infinity, which Python's json.dumps writes unless \
         allow_nan=False: a value that is not finite is a failed estimate)"
    } else {
        ""
    };
    format!(
        "answered {:?}, which is not a response ({e}){hint}",
        crate::error::excerpt(&one_line(text))
    )
}

/// Reads `stdout` line by line into `send` until it ends, fails, a line
/// passes `limit` bytes, or `send` refuses.
fn read_lines(
    stdout: impl Read,
    limit: &AtomicUsize,
    send: impl Fn(Result<String, String>) -> bool,
) {
    let mut reader = BufReader::new(stdout);
    loop {
        let cap = limit.load(Ordering::Relaxed);
        let mut line = Vec::new();
        let read = (&mut reader)
            .take(cap as u64 + 1)
            .read_until(b'\n', &mut line);
        let message = match read {
            Ok(0) => return,
            Ok(_) if line.len() > cap => Err(format!(
                "answered a line longer than {cap} bytes: expected one response of the quantity's channels"
            )),
            Ok(_) => String::from_utf8(line)
                .map(|s| s.trim_end().to_string())
                .map_err(|_| "answered a line that is not UTF-8".to_string()),
            Err(e) => Err(format!("its stdout failed: {e}")),
        };
        let fatal = message.is_err();
        if !send(message) || fatal {
            return;
        }
    }
}

/// Keeps the last [`STDERR_LINES`] lines of `stderr` (each cut to
/// [`STDERR_LINE_CHARS`]) and drops the rest, so a talkative program never
/// blocks on a full pipe.
fn keep_tail(stderr: impl Read, tail: &Mutex<VecDeque<String>>) {
    let mut reader = BufReader::new(stderr);
    let mut buf = Vec::new();
    loop {
        buf.clear();
        match (&mut reader).take(1 << 16).read_until(b'\n', &mut buf) {
            Ok(0) | Err(_) => return,
            Ok(_) => {}
        }
        let text = String::from_utf8_lossy(&buf);
        let line: String = one_line(text.trim_end())
            .chars()
            .take(STDERR_LINE_CHARS)
            .collect();
        if line.is_empty() {
            continue;
        }
        if let Ok(mut t) = tail.lock() {
            if t.len() == STDERR_LINES {
                t.pop_front();
            }
            t.push_back(line);
        }
    }
}

/// A request that got no measured value: why, and the seconds from
/// sending it to its failure (0 where it was not sent: the program did not
/// start).
#[derive(Debug)]
pub struct Unanswered {
    /// The failure, naming the request and the program's last stderr lines.
    pub why: String,
    /// Seconds from sending the request to its failure.
    pub seconds: f64,
}

/// The idle processes of each external rule of one experiment run: a lane
/// takes one (or starts one) for a job and gives it back when it served
/// well; all are stopped when this is dropped.
#[derive(Default)]
pub struct Servers {
    idle: Mutex<Vec<(usize, Server)>>,
    /// Rules whose program failed to start, with why: not started again
    /// in this run (each start would wait out its timeout once more).
    broken: Mutex<Vec<(usize, String)>>,
}

impl std::fmt::Debug for Servers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let idle = self.idle.lock().map_or(0, |v| v.len());
        write!(f, "Servers {{ idle: {idle} }}")
    }
}

impl Servers {
    /// Asks rule `rule`'s program for `request`: the measured value, its
    /// `seconds` set to lightquad's time of the request; or the job's
    /// failure, naming the request and the program's last stderr lines.
    pub fn ask(
        &self,
        rule: usize,
        program: &Program,
        request: Request,
        timeout_s: f64,
    ) -> Result<Measured, Unanswered> {
        let taken = self.idle.lock().ok().and_then(|mut idle| {
            let k = idle.iter().position(|(r, _)| *r == rule)?;
            Some(idle.swap_remove(k).1)
        });
        let what = format!(
            "{} at budget {}, repeat {}, seed {}",
            request.quantity, request.budget, request.repeat, request.seed
        );
        let mut server = match taken {
            Some(s) => s,
            None => self
                .start(rule, program, timeout_s)
                .map_err(|e| Unanswered {
                    why: format!("{what}: {e}"),
                    seconds: 0.0,
                })?,
        };
        match server.ask(request, Duration::from_secs_f64(timeout_s)) {
            Ok((mut m, seconds)) => {
                m.seconds = Some(seconds);
                self.give_back(rule, server);
                // The program's request lies within lightquad's timing of it.
                match m.program_seconds {
                    Some(own) if own > seconds + OWN_TIME_SLACK => Err(Unanswered {
                        why: format!(
                            "{what}: reported taking {own:.3e} s for a request that lightquad \
                             timed at {seconds:.3e} s from sending it to reading the answer"
                        ),
                        seconds,
                    }),
                    _ => Ok(m),
                }
            }
            Err((why, keep, seconds)) => {
                let tail = server
                    .stderr_tail()
                    .map(|t| format!("; its stderr ended: {t}"))
                    .unwrap_or_default();
                if keep {
                    self.give_back(rule, server);
                }
                Err(Unanswered {
                    why: format!("{what}: {why}{tail}"),
                    seconds,
                })
            }
        }
    }

    /// A fresh process of rule `rule`, unless its program failed to start
    /// before in this run (then the same failure, said to be an earlier one).
    fn start(&self, rule: usize, program: &Program, timeout_s: f64) -> Result<Server, String> {
        let earlier = self.broken.lock().ok().and_then(|broken| {
            broken
                .iter()
                .find(|(r, _)| *r == rule)
                .map(|(_, why)| why.clone())
        });
        if let Some(why) = earlier {
            return Err(format!(
                "its program failed to start earlier in this run and is not started again: {why}"
            ));
        }
        Server::start(program, Duration::from_secs_f64(timeout_s)).inspect_err(|why| {
            if let Ok(mut broken) = self.broken.lock() {
                broken.push((rule, why.clone()));
            }
        })
    }

    fn give_back(&self, rule: usize, server: Server) {
        if let Ok(mut idle) = self.idle.lock() {
            idle.push((rule, server));
        }
    }
}

/// A `sh` process that holds the ids of the running programs and, when its
/// stdin ends (lightquad exited, however it was stopped, kill -9 included),
/// kills those still listed with their process groups: no program
/// outlives the run that started it.
pub struct Watcher {
    stdin: Mutex<Option<ChildStdin>>,
}

/// The watcher's script: `+pid` lists a program, `-pid` strikes it off.
const WATCH: &str = r#"trap '' INT TERM HUP
pids=' '
while read -r line; do
  case "$line" in
    +*) pids="$pids${line#+} " ;;
    -*) pids=$(printf '%s' "$pids" | sed "s/ ${line#-} / /") ;;
  esac
done
for p in $pids; do kill -9 -- "-$p" 2>/dev/null; kill -9 "$p" 2>/dev/null; done"#;

impl Watcher {
    /// The process's watcher, started on first use (none if `sh` cannot be
    /// started: the programs then still stop when their stdin ends).
    pub fn get() -> &'static Watcher {
        static WATCHER: OnceLock<Watcher> = OnceLock::new();
        WATCHER.get_or_init(|| {
            let stdin = Command::new("sh")
                .args(["-c", WATCH])
                .stdin(Stdio::piped())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .ok()
                .and_then(|mut c| c.stdin.take());
            Watcher {
                stdin: Mutex::new(stdin),
            }
        })
    }

    fn tell(&self, line: String) {
        if let Ok(mut stdin) = self.stdin.lock()
            && let Some(s) = stdin.as_mut()
        {
            let _ = s.write_all(line.as_bytes()).and_then(|()| s.flush());
        }
    }

    /// Lists program `pid`.
    pub fn watch(&self, pid: u32) {
        self.tell(format!("+{pid}\n"));
    }

    /// Strikes program `pid` off (it has been stopped and waited for).
    pub fn forget(&self, pid: u32) {
        self.tell(format!("-{pid}\n"));
    }
}
