//! Sealed binary files (`shard.bin`, `checkpoint.bin`): a header naming the kind of file and
//! its format version, the payload, and a SHA-256 digest of everything before it. Any change to
//! any byte (a flipped bit, a truncated copy, a file of another kind or format) is refused with
//! an error before the payload is decoded, so a damaged file can never turn into a table.
//!
//! Layout: `SMITHWLK` (8 bytes), kind (1 byte), format version (u32 LE), payload length (u64
//! LE), payload, SHA-256 of all preceding bytes (32 bytes).

use anyhow::{Result, bail, ensure};
use sha2::{Digest, Sha256};

const MAGIC: &[u8; 8] = b"SMITHWLK";
const HEADER: usize = 8 + 1 + 4 + 8;
const DIGEST: usize = 32;

/// What a sealed file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Shard,
    Checkpoint,
}

impl Kind {
    fn code(self) -> u8 {
        match self {
            Kind::Shard => 1,
            Kind::Checkpoint => 2,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Kind::Shard => "shard",
            Kind::Checkpoint => "checkpoint",
        }
    }
}

/// The payload format this build writes and reads (format 1 had no header or digest).
pub const FORMAT_VERSION: u32 = 3;

/// The payload in a sealed envelope of `kind`.
pub fn seal(kind: Kind, payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER + payload.len() + DIGEST);
    bytes.extend_from_slice(MAGIC);
    bytes.push(kind.code());
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(payload);
    let digest = Sha256::digest(&bytes);
    bytes.extend_from_slice(&digest);
    bytes
}

/// The payload of a sealed file of `kind`, after checking its digest, kind, version and length;
/// `origin` names the file in errors.
pub fn unseal<'a>(kind: Kind, bytes: &'a [u8], origin: &str) -> Result<&'a [u8]> {
    let what = kind.name();
    if bytes.len() < HEADER + DIGEST || &bytes[..8] != MAGIC {
        bail!(
            "{origin} is not a smithwalk {what} file (or was written by a smithwalk older than format {})",
            FORMAT_VERSION
        );
    }
    let (body, digest) = bytes.split_at(bytes.len() - DIGEST);
    ensure!(
        Sha256::digest(body).as_slice() == digest,
        "{origin} is corrupt: its SHA-256 checksum does not match its content (a damaged or truncated copy); \
         rerun what wrote it"
    );
    ensure!(
        bytes[8] == kind.code(),
        "{origin} is a smithwalk {} file, not a {what} file",
        if bytes[8] == Kind::Shard.code() { "shard" } else { "checkpoint or other" }
    );
    let version = u32::from_le_bytes(bytes[9..13].try_into().expect("4 bytes"));
    ensure!(
        version == FORMAT_VERSION,
        "{origin}: {what} format {version}, but this smithwalk reads format {}",
        FORMAT_VERSION
    );
    let len = u64::from_le_bytes(bytes[13..21].try_into().expect("8 bytes"));
    let payload = &body[HEADER..];
    ensure!(len == payload.len() as u64, "{origin} is corrupt: {len} bytes announced, {} present", payload.len());
    Ok(payload)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_single_byte_change_is_refused() {
        let sealed = seal(Kind::Shard, b"the accumulators");
        assert_eq!(unseal(Kind::Shard, &sealed, "x").unwrap(), b"the accumulators");
        for i in 0..sealed.len() {
            for flip in [0x01, 0xff] {
                let mut bad = sealed.clone();
                bad[i] ^= flip;
                assert!(unseal(Kind::Shard, &bad, "x").is_err(), "byte {i} xor {flip:#x} accepted");
            }
        }
        assert!(unseal(Kind::Checkpoint, &sealed, "x").is_err(), "a shard read as a checkpoint");
        assert!(unseal(Kind::Shard, &sealed[..sealed.len() - 1], "x").is_err(), "a truncated file");
    }
}
