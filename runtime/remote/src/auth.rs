//! Who may speak in a multi-host run: one secret key per host, shared by the world and that host only.
//!
//! A host's key does two things:
//!
//! - **Admission.** zenoh's user/password check at every connection: the host presents its name and a password
//!   derived from its key; the world accepts exactly the hosts of its key folder. A machine without a key
//!   cannot open a session with the world, so it can neither send nor listen.
//! - **Message authentication.** Every message between the world and a host carries an HMAC-SHA256 tag over
//!   the message's channel (its zenoh key expression, and for an answer the request it answers) and its bytes,
//!   keyed with that host's key ([`Seal`]). A message is checked before anything decodes it; one that fails is
//!   dropped and counted. Because each host has its own key, one host cannot speak for another: a batch of
//!   replies on host B's key must carry B's tag, which host A cannot make.
//!
//! Replays of genuine messages are caught by what the messages carry: run, epoch, tick windows and order
//! numbers (see `host.rs` and `world_bridge.rs`). Keys are 32 random bytes stored as hex in a file only its owner
//! can read (`swarm host-key`); docs/hosts.md, "Security", tells the operator's side.

use std::collections::HashMap;
use std::io::Read;
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use ring::hmac;
use ring::rand::{SecureRandom, SystemRandom};
use subtle::ConstantTimeEq;

/// Bytes of a host key.
pub const KEY_LEN: usize = 32;
/// Bytes of the tag appended to every authenticated message.
pub const TAG_LEN: usize = 32;
/// Largest key file read (a key file is one line of hex).
const MAX_KEY_FILE: u64 = 1024;
/// What the admission password is derived from, so it never equals a message tag.
const ADMISSION_CONTEXT: &[u8] = b"swarm zenoh admission v1";

/// Why a key cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum KeyError {
    /// The key file cannot be read or written.
    #[error("{what} {path}: {source}")]
    Io {
        /// What was being done.
        what: &'static str,
        /// The key file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The key file does not hold a key.
    #[error("{path}: {reason}")]
    Malformed {
        /// The key file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The key file can be read by other users.
    #[error(
        "{path} can be read by other users (mode {mode:04o}); a host key must be private: chmod 600 {path}"
    )]
    NotPrivate {
        /// The key file.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
    },
    /// The system's random source failed.
    #[error("drawing a random key failed")]
    Random,
}

/// One host's secret key.
pub struct HostKey {
    key: hmac::Key,
    admission: String,
}

impl std::fmt::Debug for HostKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("HostKey(..)")
    }
}

impl HostKey {
    /// The key made of `secret`.
    pub fn from_secret(secret: &[u8; KEY_LEN]) -> HostKey {
        let key = hmac::Key::new(hmac::HMAC_SHA256, secret);
        let admission = hex(hmac::sign(&key, ADMISSION_CONTEXT).as_ref());
        HostKey { key, admission }
    }

    /// Reads a key file: one line of 64 hex digits, readable by its owner only.
    pub fn read(path: &Path) -> Result<HostKey, KeyError> {
        let io = |what| {
            move |source| KeyError::Io {
                what,
                path: path.to_owned(),
                source,
            }
        };
        let malformed = |reason: &str| KeyError::Malformed {
            path: path.to_owned(),
            reason: reason.to_owned(),
        };
        let file = std::fs::File::open(path).map_err(io("reading the host key"))?;
        let meta = file.metadata().map_err(io("reading the host key"))?;
        if !meta.is_file() {
            return Err(malformed("not a regular file"));
        }
        if meta.mode() & 0o077 != 0 {
            return Err(KeyError::NotPrivate {
                path: path.to_owned(),
                mode: meta.mode() & 0o7777,
            });
        }
        let mut text = String::new();
        file.take(MAX_KEY_FILE)
            .read_to_string(&mut text)
            .map_err(io("reading the host key"))?;
        let digits = text.trim();
        if digits.len() != 2 * KEY_LEN {
            return Err(malformed(&format!(
                "a host key is {} hex digits, found {} characters",
                2 * KEY_LEN,
                digits.len()
            )));
        }
        let mut secret = [0u8; KEY_LEN];
        for (byte, pair) in secret.iter_mut().zip(digits.as_bytes().chunks(2)) {
            let pair = std::str::from_utf8(pair).map_err(|_| malformed("not hex digits"))?;
            *byte = u8::from_str_radix(pair, 16).map_err(|_| malformed("not hex digits"))?;
        }
        Ok(HostKey::from_secret(&secret))
    }

    /// Draws a new random key and writes it to `path` (which must not exist), readable by its owner only.
    pub fn create(path: &Path) -> Result<HostKey, KeyError> {
        let mut secret = [0u8; KEY_LEN];
        SystemRandom::new()
            .fill(&mut secret)
            .map_err(|_| KeyError::Random)?;
        let io = |what| {
            move |source| KeyError::Io {
                what,
                path: path.to_owned(),
                source,
            }
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io("creating the folder of"))?;
        }
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(path)
            .map_err(io("creating the host key"))?;
        std::io::Write::write_all(&mut file, format!("{}\n", hex(&secret)).as_bytes())
            .and_then(|()| file.sync_all())
            .map_err(io("writing the host key"))?;
        Ok(HostKey::from_secret(&secret))
    }

    /// The password the host presents to zenoh's user/password check (derived from the key, never the key).
    pub fn admission_password(&self) -> &str {
        &self.admission
    }
}

/// Lower-case hex of `bytes`.
fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Why a message was not accepted as authentic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum AuthError {
    /// Shorter than a tag.
    #[error("an authenticated message of {0} bytes is shorter than its tag")]
    Short(usize),
    /// The tag does not match: not made with this host's key, or for another channel, or altered.
    #[error("the message's tag does not match its sender's key")]
    BadTag,
}

/// How the messages of one host's channels are protected: tagged with its key, or not at all (a run with
/// authentication turned off).
#[derive(Debug, Clone)]
pub enum Seal {
    /// No tag: anyone who reaches the endpoint can speak (`--insecure-hosts`).
    Off,
    /// Tagged with this host's key.
    Key(Arc<HostKey>),
}

impl Seal {
    /// Whether messages are tagged.
    pub fn is_on(&self) -> bool {
        matches!(self, Seal::Key(_))
    }

    /// The tag of `payload` on `channel`.
    fn tag(key: &HostKey, channel: &str, payload: &[u8]) -> hmac::Tag {
        let mut context = hmac::Context::with_key(&key.key);
        context.update(&(channel.len() as u64).to_le_bytes());
        context.update(channel.as_bytes());
        context.update(payload);
        context.sign()
    }

    /// Appends the tag of the bytes in `message` on `channel` (nothing when off).
    pub fn seal(&self, channel: &str, message: &mut Vec<u8>) {
        if let Seal::Key(key) = self {
            let tag = Seal::tag(key, channel, message);
            message.extend_from_slice(tag.as_ref());
        }
    }

    /// The payload of an authentic `message` on `channel`, without its tag; an error when the tag is missing or
    /// wrong (compared in constant time).
    pub fn open<'a>(&self, channel: &str, message: &'a [u8]) -> Result<&'a [u8], AuthError> {
        let Seal::Key(key) = self else {
            return Ok(message);
        };
        let Some(split) = message.len().checked_sub(TAG_LEN) else {
            return Err(AuthError::Short(message.len()));
        };
        let (payload, tag) = message.split_at(split);
        if bool::from(Seal::tag(key, channel, payload).as_ref().ct_eq(tag)) {
            Ok(payload)
        } else {
            Err(AuthError::BadTag)
        }
    }
}

/// The channel of the answer to `request` sent on `channel`: an answer is bound to the request it answers, so an
/// old answer cannot be replayed for a new request.
pub fn answer_channel(channel: &str, request: &[u8]) -> String {
    let tag = &request[request.len().saturating_sub(TAG_LEN)..];
    format!("{channel}#answer:{}", hex(tag))
}

/// The default folder of host keys: `$XDG_CONFIG_HOME/swarm/keys`, else `~/.config/swarm/keys`.
pub fn default_key_dir() -> Option<PathBuf> {
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".config")))?;
    Some(config.join("swarm").join("keys"))
}

/// Where the key of host `name` lives in the key folder `dir`.
pub fn key_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.key"))
}

/// Creates the keys of the hosts in `names` that `dir` does not hold yet; returns the files created.
pub fn create_missing_keys<'a>(
    dir: &Path,
    names: impl IntoIterator<Item = &'a str>,
) -> Result<Vec<PathBuf>, KeyError> {
    let mut created = Vec::new();
    for name in names {
        let path = key_path(dir, name);
        if !path.exists() {
            HostKey::create(&path)?;
            created.push(path);
        }
    }
    Ok(created)
}

/// The keys the world holds for a run's hosts.
#[derive(Debug, Clone, Default)]
pub enum HostKeys {
    /// Authentication is off (`--insecure-hosts`).
    #[default]
    Off,
    /// One key per host, by name.
    On(HashMap<String, Arc<HostKey>>),
}

impl HostKeys {
    /// Reads the key of every host in `names` from `dir`.
    pub fn load<'a>(
        dir: &Path,
        names: impl IntoIterator<Item = &'a str>,
    ) -> Result<HostKeys, KeyError> {
        let mut keys = HashMap::new();
        for name in names {
            keys.insert(
                name.to_owned(),
                Arc::new(HostKey::read(&key_path(dir, name))?),
            );
        }
        Ok(HostKeys::On(keys))
    }

    /// How the messages of host `name` are protected; `None` when authentication is on and the host has no key.
    pub fn seal(&self, name: &str) -> Option<Seal> {
        match self {
            HostKeys::Off => Some(Seal::Off),
            HostKeys::On(keys) => keys.get(name).cloned().map(Seal::Key),
        }
    }

    /// The `user:password` pairs zenoh's admission check accepts (empty when off).
    pub fn admitted(&self) -> Vec<(String, String)> {
        match self {
            HostKeys::Off => Vec::new(),
            HostKeys::On(keys) => {
                let mut pairs: Vec<(String, String)> = keys
                    .iter()
                    .map(|(name, key)| (name.clone(), key.admission_password().to_owned()))
                    .collect();
                pairs.sort();
                pairs
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seal(byte: u8) -> Seal {
        Seal::Key(Arc::new(HostKey::from_secret(&[byte; KEY_LEN])))
    }

    #[test]
    fn a_sealed_message_opens_only_with_its_key_on_its_channel_unaltered() {
        let mut message = b"frames of tick 7".to_vec();
        seal(1).seal("swarm/a", &mut message);
        assert_eq!(
            seal(1).open("swarm/a", &message),
            Ok(&b"frames of tick 7"[..])
        );
        assert_eq!(seal(2).open("swarm/a", &message), Err(AuthError::BadTag));
        assert_eq!(seal(1).open("swarm/b", &message), Err(AuthError::BadTag));
        let mut altered = message.clone();
        altered[0] ^= 1;
        assert_eq!(seal(1).open("swarm/a", &altered), Err(AuthError::BadTag));
        assert_eq!(seal(1).open("swarm/a", &[0; 5]), Err(AuthError::Short(5)));
        assert_eq!(Seal::Off.open("swarm/a", b"plain"), Ok(&b"plain"[..]));
    }

    #[test]
    fn key_files_round_trip_and_must_be_private_and_well_formed() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("keys/h1.key");
        let created = HostKey::create(&path).unwrap();
        let read = HostKey::read(&path).unwrap();
        assert_eq!(created.admission_password(), read.admission_password());
        assert!(
            HostKey::create(&path).is_err(),
            "an existing key is never replaced"
        );

        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        let error = HostKey::read(&path).unwrap_err().to_string();
        assert!(error.contains("chmod 600"), "{error}");

        let bad = dir.path().join("bad.key");
        std::fs::write(&bad, "not a key\n").unwrap();
        std::fs::set_permissions(&bad, std::fs::Permissions::from_mode(0o600)).unwrap();
        let error = HostKey::read(&bad).unwrap_err().to_string();
        assert!(error.contains("64 hex digits"), "{error}");
        std::fs::write(&bad, "zz".repeat(KEY_LEN)).unwrap();
        let error = HostKey::read(&bad).unwrap_err().to_string();
        assert!(error.contains("not hex"), "{error}");
    }
}
