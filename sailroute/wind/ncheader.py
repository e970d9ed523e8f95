"""Check the header of a classic NetCDF file (CDF-1, CDF-2, CDF-5) before the library opens it.

The netCDF-C library allocates what a classic header declares (names, attribute values,
lists of dimensions and variables) before it checks that the file holds it; a damaged
header that declares a name of two billion characters makes it allocate gigabytes.
:func:`check_classic_header` walks the header as the format specification describes it
(Unidata, "The NetCDF Classic Format Specification", NetCDF User's Guide) and refuses
any count, length or variable that does not fit in the file, without reading more than
the header itself.  Files in the NetCDF-4 (HDF5) format are left to the library.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path
from typing import BinaryIO

from sailroute.errors import WindDataError

__all__ = ["check_classic_header"]

_ABSENT, _DIMENSION, _VARIABLE, _ATTRIBUTE = 0, 0x0A, 0x0B, 0x0C
_TYPE_SIZE = {1: 1, 2: 1, 3: 2, 4: 4, 5: 4, 6: 8, 7: 1, 8: 2, 9: 4, 10: 8, 11: 8}
"""nc_type -> bytes per value (NC_BYTE ... NC_DOUBLE; CDF-5 adds NC_UBYTE ... NC_UINT64)."""
_STREAMING = 0xFFFFFFFF


class _Damaged(Exception):
    """The header does not fit the file (the message says where)."""


class _Reader:
    """Big-endian fields of a classic header, bounded by the file size."""

    def __init__(self, fh: BinaryIO, size: int, version: int) -> None:
        self.fh, self.size = fh, size
        self.wide = version == 5  # CDF-5: 64-bit counts
        self.pos = 4

    def _take(self, n: int) -> bytes:
        if n < 0 or self.pos + n > self.size:
            raise _Damaged(f"it declares {n} bytes at offset {self.pos}, past the end")
        data = self.fh.read(n)
        self.pos += n
        return data

    def skip(self, n: int) -> None:
        if n < 0 or self.pos + n > self.size:
            raise _Damaged(f"it declares {n} bytes at offset {self.pos}, past the end")
        self.pos += n
        self.fh.seek(self.pos)

    def u32(self) -> int:
        return int(struct.unpack(">I", self._take(4))[0])

    def count(self) -> int:
        """A count or length (NON_NEG): 32 bits, 64 in CDF-5."""
        return int(struct.unpack(">Q", self._take(8))[0]) if self.wide else self.u32()

    def name(self) -> None:
        n = self.count()
        self.skip(n + (-n) % 4)

    def listed(self, tag: int, min_item: int) -> int:
        """The number of items of a list with ``tag`` (0 when absent), checked against the
        bytes left (each item takes at least ``min_item``)."""
        got, n = self.u32(), self.count()
        if got == _ABSENT and n == 0:
            return 0
        if got != tag:
            raise _Damaged(f"expected list tag {tag:#x} at offset {self.pos - 8}; got {got:#x}")
        if n * min_item > self.size - self.pos:
            raise _Damaged(f"it lists {n} items at offset {self.pos}, more than the file holds")
        return n

    def attributes(self) -> None:
        for _ in range(self.listed(_ATTRIBUTE, 12)):
            self.name()
            size = _TYPE_SIZE.get(self.u32())
            if size is None:
                raise _Damaged(f"unknown attribute type at offset {self.pos - 4}")
            nbytes = self.count() * size
            self.skip(nbytes + (-nbytes) % 4)


def check_classic_header(path: str | Path) -> None:
    """Refuse a classic NetCDF file whose header does not fit in it.

    Parameters
    ----------
    path : str or Path
        The file; anything that does not start with ``CDF\\x01``, ``CDF\\x02`` or
        ``CDF\\x05`` (NetCDF-4/HDF5, GRIB, text) passes unchecked.

    Raises
    ------
    WindDataError
        A count, name, attribute or list that runs past the end of the file, an unknown
        type, or a variable whose data (dimension lengths times value size) could not
        be in the file: the file is damaged or truncated.
    """
    p = Path(path)
    size = p.stat().st_size
    with p.open("rb") as fh:
        magic = fh.read(4)
        if len(magic) < 4 or magic[:3] != b"CDF" or magic[3] not in (1, 2, 5):
            return
        r = _Reader(fh, size, magic[3])
        try:
            numrecs = r.count()
            dims: list[int] = []
            for _ in range(r.listed(_DIMENSION, 8)):
                r.name()
                dims.append(r.count())
            r.attributes()
            for _ in range(r.listed(_VARIABLE, 16)):
                r.name()
                n_dims = r.count()
                if n_dims * (8 if r.wide else 4) > size - r.pos:
                    raise _Damaged(f"a variable with {n_dims} dimensions at offset {r.pos}")
                ids = [r.count() for _ in range(n_dims)]
                if any(i >= len(dims) for i in ids):
                    raise _Damaged(f"a variable refers to dimension {max(ids)} of {len(dims)}")
                r.attributes()
                value = _TYPE_SIZE.get(r.u32())
                if value is None:
                    raise _Damaged(f"unknown variable type at offset {r.pos - 4}")
                r.count()  # vsize (rounded, may wrap for large variables: not used)
                r.skip(4 if magic[3] == 1 else 8)  # begin
                lengths = [
                    numrecs if dims[i] == 0 and numrecs != _STREAMING else dims[i] for i in ids
                ]
                if math.prod(lengths) * value > size:
                    raise _Damaged(
                        f"a variable of {' x '.join(map(str, lengths))} values "
                        f"({value} bytes each) in a file of {size} bytes"
                    )
        except _Damaged as exc:
            raise WindDataError(
                f"{p}: damaged NetCDF file: {exc}; expected a complete classic "
                "NetCDF file (download or copy it again)"
            ) from None
