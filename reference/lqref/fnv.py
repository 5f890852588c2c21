"""FNV-1a 64-bit hash of an experiment file's exact bytes.

The same function as lightquad's ``experiment::run::file_hash``: offset basis
0xcbf29ce484222325, prime 0x100000001b3, for each byte xor then multiply,
wrapping at 64 bits, written as 16 lowercase hex digits. A values file records
the hash of the experiment file it was computed from, so a changed experiment
file shows its values as stale.
"""

FNV_OFFSET = 0xCBF29CE484222325
FNV_PRIME = 0x100000001B3
MASK64 = (1 << 64) - 1


def fnv1a64(data: bytes) -> str:
    """The FNV-1a 64-bit hash of ``data`` as 16 lowercase hex digits."""
    h = FNV_OFFSET
    for byte in data:
        h ^= byte
        h = (h * FNV_PRIME) & MASK64
    return f"{h:016x}"


def file_hash(path) -> str:
    """The FNV-1a 64-bit hash of the file at ``path`` (its exact bytes)."""
    with open(path, "rb") as f:
        return fnv1a64(f.read())
