"""What the readers' fuzz tests share: settings, byte mutations, and memory and time limits per example.

The default run is deterministic and short; ``MOCYCLE_FUZZ_EXAMPLES=5000`` hunts longer with fresh random
examples.  Each example runs under a memory limit (``RLIMIT_AS`` of the test process raised by
:data:`MEMORY_HEADROOM` over what it already maps, restored after) and a hard time limit (``SIGALRM``), so
an allocation bomb fails the test with ``MemoryError`` and a hang with :class:`ExampleTimeout` instead of
taking the machine down.
"""

from __future__ import annotations

import contextlib
import os
import signal
import zlib

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

try:
    import resource
except ImportError:  # pragma: no cover - not on Linux/macOS
    resource = None

_HUNT = os.environ.get("MOCYCLE_FUZZ_EXAMPLES")


def fuzz_settings(examples: int = 100, deadline_ms: int = 3000) -> settings:
    return settings(
        max_examples=int(_HUNT or examples),
        derandomize=not _HUNT,
        database=None,
        deadline=deadline_ms,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
    )


#: Memory an example may map beyond what the process already has (bytes).
MEMORY_HEADROOM = 1 << 30
#: Wall-clock seconds an example may take before it counts as a hang.
TIME_LIMIT_S = 10.0


class ExampleTimeout(Exception):
    """An example ran past :data:`TIME_LIMIT_S`."""


def _mapped_bytes() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


@contextlib.contextmanager
def limits(headroom: int = MEMORY_HEADROOM, seconds: float = TIME_LIMIT_S):
    """Run the block with at most ``headroom`` more bytes of address space and ``seconds`` of wall time."""
    can_limit = resource is not None and os.path.exists("/proc/self/statm")
    if can_limit:
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        cap = _mapped_bytes() + headroom
        if hard != resource.RLIM_INFINITY:
            cap = min(cap, hard)
        resource.setrlimit(resource.RLIMIT_AS, (cap, hard))

    def _alarm(signum, frame):
        raise ExampleTimeout(f"example ran longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        if can_limit:
            resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


#: Byte values that make counts and sizes absurd when they land in a length field.
INTERESTING = [b"\x00", b"\xff", b"\x7f", b"\x80", b"\x00\x00\x00\x00", b"\xff\xff\xff\xff",
               b"\x00\xca\x9a\x3b", b"\x00\x00\x80\x7f", b"\x00\x00\xc0\x7f", b"\x01\x00\x00\x00",
               b"\xff\xff\xff\x7f", b"\x00\x00\x00\x80"]


@st.composite
def mutated(draw, base: bytes, max_edits: int = 6, same_size: bool = False) -> bytes:
    """``base`` after 1-``max_edits`` edits: byte flips, interesting values, deletions, insertions, splices
    (only flips and overwrites when ``same_size``)."""
    data = bytearray(base)
    ops = ["flip", "value"] if same_size else ["flip", "value", "value", "delete", "insert", "dup", "truncate"]
    for _ in range(draw(st.integers(1, max_edits))):
        op = draw(st.sampled_from(ops))
        pos = draw(st.integers(0, max(len(data) - 1, 0)))
        if op == "flip" and data:
            data[pos] ^= 1 << draw(st.integers(0, 7))
        elif op == "value":
            chunk = draw(st.sampled_from(INTERESTING))[:len(data) - pos] if same_size else draw(
                st.sampled_from(INTERESTING))
            data[pos:pos + len(chunk)] = chunk
        elif op == "delete":
            del data[pos:pos + draw(st.integers(1, 64))]
        elif op == "insert":
            data[pos:pos] = draw(st.binary(min_size=1, max_size=16))
        elif op == "dup":
            n = draw(st.integers(1, 256))
            data[pos:pos] = data[pos:pos + n] * draw(st.integers(1, 4))
        elif op == "truncate":
            del data[pos:]
    return bytes(data)


def zlib_file(magic: bytes, payload: bytes) -> bytes:
    return magic + zlib.compress(payload, 6)


@st.composite
def mutated_zlib_file(draw, magic: bytes, payload: bytes) -> bytes:
    """A ``magic + zlib(payload)`` file damaged inside the payload (re-compressed) or in its bytes."""
    if draw(st.integers(0, 3)) == 0:
        return draw(mutated(zlib_file(magic, payload)))
    return zlib_file(magic, draw(mutated(payload)))


@st.composite
def edited_text(draw, base: str, vocab: list[str], max_edits: int = 6) -> str:
    """``base`` after 1-``max_edits`` edits of characters, words (from ``vocab`` or absurd numbers) or lines."""
    text = base
    word = st.one_of(st.sampled_from(vocab), st.sampled_from(["nan", "inf", "-inf", "1e308", "-1e400", "0", "",
                                                              "1e-320", "99999999999999999999", "#", ":"]),
                     st.floats().map(repr), st.integers(-3, 10**12).map(str), st.characters().map(str))
    for _ in range(draw(st.integers(1, max_edits))):
        lines = text.split("\n")
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["word", "word", "char", "dup_line", "drop_line", "swap_lines", "truncate"]))
        if op == "word":
            words = lines[i].split(" ")
            k = draw(st.integers(0, len(words)))
            words[k:k + draw(st.integers(0, 1))] = [draw(word)] if draw(st.booleans()) else []
            lines[i] = " ".join(words)
        elif op == "char":
            pos = draw(st.integers(0, len(lines[i])))
            lines[i] = lines[i][:pos] + draw(st.characters()) + lines[i][pos + draw(st.integers(0, 1)):]
        elif op == "dup_line":
            lines[i:i + 1] = [lines[i]] * draw(st.integers(2, 4))
        elif op == "drop_line":
            del lines[i]
        elif op == "swap_lines":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        else:
            del lines[i:]
        text = "\n".join(lines)
    return text
