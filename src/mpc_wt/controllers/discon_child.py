"""The child process in which :class:`mpc_wt.controllers.discon.DisconController` runs a
Bladed-style controller library, so that a library that calls ``exit()``, aborts or crashes
ends this process and not the simulation's.

Run as a script (``python -I discon_child.py LIBRARY LOG SHARED INFILE OUTNAME SWAP MSG OUT
[DEP ...]``); it imports nothing but the standard library. The swap array (``SWAP`` float32
values) lives in the file ``SHARED``, mapped by both processes; the child's standard input and
output carry the rest, and what the library prints goes to ``LOG``:

- once, child to parent: ``b"OK"`` when the library is loaded, or ``b"NO"``, a 4-byte length
  and the reason;
- per call, parent to child: one byte (the swap array is in place); child to parent: the
  ``aviFAIL`` value and the message length (two little-endian int32) and the message, the swap
  array as the library left it.

The parent closes the child's standard input to end it.
"""
from __future__ import annotations

import ctypes
import mmap
import os
import struct
import sys


def _read_exact(fd: int, buf: memoryview) -> bool:
    """Fill ``buf`` from ``fd``; False when the other end closed first."""
    got = 0
    while got < len(buf):
        n = os.readv(fd, [buf[got:]])
        if n == 0:
            return False
        got += n
    return True


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _preload(paths: list[str]) -> None:
    """The runtime libraries a wheel bundles beside the library, loaded globally in passes
    (they depend on each other) so that the library finds them by their sonames."""
    left = list(paths)
    for _ in range(3):
        failed = []
        for p in left:
            try:
                ctypes.CDLL(p, mode=getattr(ctypes, "RTLD_GLOBAL", 0))
            except OSError:
                failed.append(p)
        if not failed or len(failed) == len(left):
            return
        left = failed


def _main(argv: list[str]) -> int:
    library, log_path, shared, infile, outname = argv[:5]
    n_swap, msg_len, out_len = (int(a) for a in argv[5:8])
    proto_in, proto_out = os.dup(0), os.dup(1)
    log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
    os.dup2(log, 1)                      # the library's prints go to the log, not the protocol
    os.dup2(log, 2)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    _preload(argv[8:])
    try:
        fn = ctypes.CDLL(library, mode=getattr(ctypes, "RTLD_LOCAL", 0)).DISCON
    except (OSError, AttributeError) as err:
        why = str(err).encode(errors="replace")
        _write_all(proto_out, b"NO" + struct.pack("<i", len(why)) + why)
        return 1
    fn.restype = None
    fn.argtypes = [ctypes.POINTER(ctypes.c_float), ctypes.POINTER(ctypes.c_int),
                   ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p]
    with open(shared, "r+b") as fh:
        mem = mmap.mmap(fh.fileno(), n_swap * 4)
    swap = (ctypes.c_float * n_swap).from_buffer(mem)
    go = memoryview(bytearray(1))
    fail = ctypes.c_int(0)
    msg = ctypes.create_string_buffer(msg_len)
    out = ctypes.create_string_buffer(out_len)
    infile_b, outname_b = infile.encode(), outname.encode() + b"\0"
    _write_all(proto_out, b"OK")
    while _read_exact(proto_in, go):
        fail.value = 0
        msg[0] = b"\0"
        ctypes.memmove(out, outname_b, len(outname_b))
        fn(swap, ctypes.byref(fail), infile_b, out, msg)
        text = msg.value
        _write_all(proto_out, struct.pack("<ii", fail.value, len(text)) + text)
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
