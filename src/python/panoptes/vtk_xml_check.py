"""What a VTK XML file (.vti, .vtr, .vts, .vtm) claims, checked before VTK sees it (issue 44).

VTK's XML readers trust the file: an extent of 10^15 points in a 2.7 kB file makes VTK abort, XML nested
10^5 deep crashes it, an appended zlib block header is believed. This module reads the file's XML
header with a bounded, non-recursive scanner (mmap and `find`, no XML library, no entity expansion)
and refuses, with one line naming the file and the value, a file that

  - nests elements deeper than MAX_DEPTH (VTK files nest 6 deep) or holds more than MAX_ELEMENTS
    elements, has a DOCTYPE/ENTITY (VTK never writes one) or a tag it cannot finish;
  - claims an extent whose arrays (points x components x type size, summed) exceed the memory limit;
  - claims more data than the file holds: an uncompressed array larger than its bytes in the file, an
    appended or inline block whose header (byte count, or compressed blocks: count, block size, last
    size, compressed sizes) disagrees with the extent or runs past the end of the file, or more
    compressed blocks than the file has bytes for.

scan(path, max_bytes) -> Header (the dataset type, extents, arrays and `need`, the bytes VTK will hold);
blocks(path) -> the (name, file) data sets of a .vtm multi-block file."""
import base64
import mmap
import os
import re
import struct
from dataclasses import dataclass, field
from pathlib import Path

MAX_DEPTH = 32          # VTKFile/ImageData/Piece/PointData/DataArray is 5; a .vtm's blocks add a few
MAX_ELEMENTS = 100_000  # a file with 10^5 arrays or blocks is not one frame of a simulation
MAX_TAG = 1 << 16       # bytes of one start tag (its attributes)

TYPES = {"Int8": 1, "UInt8": 1, "Int16": 2, "UInt16": 2, "Int32": 4, "UInt32": 4, "Int64": 8, "UInt64": 8,
         "Float32": 4, "Float64": 8}
DATASETS = {".vti": "ImageData", ".vtr": "RectilinearGrid", ".vts": "StructuredGrid",
            ".vtm": "vtkMultiBlockDataSet"}
# The most a compressor can shrink data (zlib's deflate: 1032:1; LZ4: 255:1); LZMA has no small bound.
RATIO = {"vtkZLibDataCompressor": 1032, "vtkLZ4DataCompressor": 256}

_NAME = rb"[A-Za-z_][\w.:-]*"
_START = re.compile(rb"<(" + _NAME + rb")((?:\s+" + _NAME + rb"\s*=\s*(?:\"[^\"<]*\"|'[^'<]*'))*)\s*(/?)>")
_ATTR = re.compile(rb"(" + _NAME + rb")\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
_END = re.compile(rb"</(" + _NAME + rb")\s*>")


class Refused(ValueError):
    """A file refused before VTK read it."""


@dataclass
class Array:
    name: str
    where: str          # PointData | CellData | Points | Coordinates | FieldData
    type: str
    components: int
    format: str         # ascii | binary | appended
    offset: int = 0     # appended: from the byte after '_'
    content: tuple = (0, 0)  # inline: [start, end) of the element's text in the file
    tuples: int = 0
    piece: int = 0      # index of its <Piece>
    ordinal: int = 0    # Coordinates: 0 x, 1 y, 2 z

    @property
    def nbytes(self):
        return self.tuples * self.components * TYPES[self.type]


@dataclass
class Header:
    path: str
    type: str
    byte_order: str = "LittleEndian"
    header_type: str = "UInt32"
    compressor: str = ""
    whole_extent: tuple = ()
    pieces: list = field(default_factory=list)   # extents
    arrays: list = field(default_factory=list)
    datasets: list = field(default_factory=list)  # .vtm: (name, file)
    appended: tuple = (0, 0)  # [start, end) of the appended data (after '_')
    encoding: str = ""        # of the appended data: raw | base64
    need: int = 0             # bytes of all arrays VTK holds once it has read the file

    def points(self):
        return sum(_count(e, 0) for e in self.pieces)


def _mb(n):
    return f"{n / 1e9:.3g} GB" if n >= 1e9 else f"{n / 1e6:.3g} MB" if n >= 1e6 else f"{n} bytes"


def _count(extent, cell):
    n = 1
    for a in range(3):
        n *= max(extent[2 * a + 1] - extent[2 * a] + 1 - cell, 1 if cell else 0)
    return n


def _attrs(text):
    return {m.group(1).decode("latin-1"): (m.group(2) if m.group(2) is not None else m.group(3)).decode("latin-1")
            for m in _ATTR.finditer(text)}


def _ints(path, what, text, n):
    parts = text.split()
    if len(parts) != n:
        raise Refused(f"{path}: {what}=\"{text[:60]}\": expected {n} integers")
    try:
        v = tuple(int(p) for p in parts)
    except ValueError:
        raise Refused(f"{path}: {what}=\"{text[:60]}\": expected {n} integers") from None
    if any(abs(x) > 2**31 - 1 for x in v):
        raise Refused(f"{path}: {what}=\"{text[:60]}\": an index beyond 32 bits")
    return v


def _elements(path, mm):
    """Yields (kind, name, attrs, position, tag_end) for the file's start ('start'), empty ('empty') and end
    ('end') tags, stopping at the appended data. Bounded: no recursion, depth and count limits."""
    pos, n, depth, stack, size = 0, 0, 0, [], len(mm)
    while True:
        lt = mm.find(b"<", pos)
        if lt < 0:
            if stack:
                raise Refused(f"{path}: the file ends inside <{stack[-1]}> (truncated?)")
            return
        head = mm[lt:lt + 9]
        if head.startswith(b"<?"):
            e = mm.find(b"?>", lt)
            if e < 0:
                raise Refused(f"{path}: an unterminated <?...?> at byte {lt}")
            pos = e + 2
            continue
        if head.startswith(b"<!--"):
            e = mm.find(b"-->", lt)
            if e < 0:
                raise Refused(f"{path}: an unterminated comment at byte {lt}")
            pos = e + 3
            continue
        if head.startswith(b"<!"):
            raise Refused(f"{path}: a {head.decode('latin-1', 'replace').strip()}... declaration at byte {lt}; "
                          "VTK XML files have none (refused: entities and DOCTYPEs are not read)")
        if head.startswith(b"</"):
            m = _END.match(mm, lt, min(size, lt + 512))
            if not m:
                raise Refused(f"{path}: a malformed end tag at byte {lt}")
            name = m.group(1).decode("latin-1")
            if not stack or stack[-1] != name:
                raise Refused(f"{path}: </{name}> at byte {lt} closes "
                              + (f"<{stack[-1]}>" if stack else "nothing") + " (not well-formed XML)")
            stack.pop()
            yield "end", name, None, lt, m.end()
            pos = m.end()
            continue
        m = _START.match(mm, lt, min(size, lt + MAX_TAG))
        if not m:
            raise Refused(f"{path}: a malformed or over-long (> {MAX_TAG} bytes) tag at byte {lt}")
        n += 1
        if n > MAX_ELEMENTS:
            raise Refused(f"{path}: more than {MAX_ELEMENTS} XML elements; a VTK file of one grid has a few dozen")
        name = m.group(1).decode("latin-1")
        attrs = _attrs(m.group(2))
        if m.group(3):
            yield "empty", name, attrs, lt, m.end()
        else:
            stack.append(name)
            if len(stack) > MAX_DEPTH:
                raise Refused(f"{path}: XML elements nested deeper than {MAX_DEPTH} (at byte {lt}); "
                              "a VTK file nests 5 to 8 deep")
            yield "start", name, attrs, lt, m.end()
            if name == "AppendedData":
                return
        pos = m.end()


def _parse(path, mm):
    ext = Path(path).suffix.lower()
    h = None
    where = ""
    current = None
    block_names = []
    for kind, name, attrs, lt, end in _elements(path, mm):
        if kind == "end":
            if name in ("PointData", "CellData", "Points", "Coordinates", "FieldData"):
                where = ""
            elif name == "DataArray" and current is not None:
                current.content = (current.content[0], lt)
                current = None
            elif name == "Block" and block_names:
                block_names.pop()
            continue
        if h is None:
            if name != "VTKFile":
                raise Refused(f"{path}: starts with <{name}>; expected a VTK XML file (<VTKFile type=...>)")
            want = DATASETS[ext]
            if attrs.get("type") != want:
                raise Refused(f"{path}: a VTK XML file of type {attrs.get('type')!r}; a {ext} file holds {want}")
            h = Header(path, want, attrs.get("byte_order", "LittleEndian"), attrs.get("header_type", "UInt32"),
                       attrs.get("compressor", ""))
            if h.byte_order not in ("LittleEndian", "BigEndian"):
                raise Refused(f"{path}: byte_order {h.byte_order!r}; expected LittleEndian or BigEndian")
            if h.header_type not in ("UInt32", "UInt64"):
                raise Refused(f"{path}: header_type {h.header_type!r}; expected UInt32 or UInt64")
            if h.compressor not in ("", "vtkZLibDataCompressor", "vtkLZ4DataCompressor", "vtkLZMADataCompressor"):
                raise Refused(f"{path}: compressor {h.compressor!r}; VTK knows vtkZLibDataCompressor, "
                              "vtkLZ4DataCompressor and vtkLZMADataCompressor")
            continue
        if name == h.type and "WholeExtent" in attrs:
            h.whole_extent = _ints(path, "WholeExtent", attrs["WholeExtent"], 6)
        elif name == "Piece" and h.type != "vtkMultiBlockDataSet":
            h.pieces.append(_ints(path, "Extent", attrs.get("Extent", ""), 6))
            if len(h.pieces) > 1024:
                raise Refused(f"{path}: more than 1024 pieces")
        elif name in ("PointData", "CellData", "Points", "Coordinates", "FieldData"):
            where = name if kind == "start" else ""
        elif name == "DataArray":
            if not where:
                raise Refused(f"{path}: a DataArray outside PointData, CellData, Points or Coordinates")
            t = attrs.get("type", "")
            if t not in TYPES:
                raise Refused(f"{path}: array {attrs.get('Name', '?')!r} of type {t!r}; expected one of "
                              f"{', '.join(TYPES)}")
            try:
                comps = int(attrs.get("NumberOfComponents", "1"))
                offset = int(attrs.get("offset", "0"))
                tuples = int(attrs["NumberOfTuples"]) if "NumberOfTuples" in attrs else -1
            except ValueError:
                raise Refused(f"{path}: array {attrs.get('Name', '?')!r}: a non-integer NumberOfComponents, "
                              "NumberOfTuples or offset") from None
            if not 1 <= comps <= 1024 or offset < 0 or tuples > 2**40:
                raise Refused(f"{path}: array {attrs.get('Name', '?')!r}: NumberOfComponents {comps}, "
                              f"offset {offset}, NumberOfTuples {tuples}; out of range")
            fmt = attrs.get("format", "ascii")
            if fmt not in ("ascii", "binary", "appended"):
                raise Refused(f"{path}: array {attrs.get('Name', '?')!r}: format {fmt!r}; expected ascii, binary "
                              "or appended")
            a = Array(attrs.get("Name", ""), where, t, comps, fmt, offset, (end, end), tuples)
            a.piece = len(h.pieces) - 1
            a.ordinal = sum(1 for b in h.arrays[-3:] if b.where == where and b.piece == a.piece)
            h.arrays.append(a)
            if len(h.arrays) > 4096:
                raise Refused(f"{path}: more than 4096 arrays")
            if kind == "start":
                current = a
        elif name == "Block":
            block_names.append(attrs.get("name", attrs.get("index", "")))
        elif name in ("DataSet", "Piece") and h.type == "vtkMultiBlockDataSet":
            if "file" in attrs:
                label = "/".join([b for b in block_names if b] + [attrs.get("name", attrs.get("index", ""))])
                h.datasets.append((label.strip("/"), attrs["file"]))
        elif name == "AppendedData":
            h.encoding = attrs.get("encoding", "raw")
            if h.encoding not in ("raw", "base64"):
                raise Refused(f"{path}: AppendedData encoding {h.encoding!r}; expected raw or base64")
            u = mm.find(b"_", end)
            if u < 0:
                raise Refused(f"{path}: AppendedData without its '_' marker")
            close = mm.rfind(b"</AppendedData>")
            h.appended = (u + 1, close if close > u else len(mm))
    if h is None:
        raise Refused(f"{path}: no <VTKFile> element: not a VTK XML file")
    return h


class _Source:
    """A block's bytes: raw appended data, or base64 text (appended base64, inline binary) decoded on demand."""

    def __init__(self, mm, start, end, b64):
        self.mm, self.start, self.end, self.b64 = mm, start, end, b64
        if b64:  # skip leading whitespace of inline text
            while self.start < end and mm[self.start:self.start + 1] in b" \t\r\n":
                self.start += 1

    def available(self):
        """Bytes the block's source can hold (decoded)."""
        n = self.end - self.start
        return n * 3 // 4 if self.b64 else n

    def read(self, nbytes, skip_b64_groups=0):
        """The first nbytes of the (decoded) stream; base64: starting skip_b64_groups*4 characters in."""
        if not self.b64:
            if self.start + nbytes > self.end:
                return None
            return bytes(self.mm[self.start:self.start + nbytes])
        chars = (nbytes + 2) // 3 * 4
        s = self.start + skip_b64_groups * 4
        text = bytes(self.mm[s:min(self.end, s + chars + chars // 8 + 64)])
        text = re.sub(rb"\s+", b"", text)[:chars]
        if len(text) < chars:
            return None
        try:
            return base64.b64decode(text, validate=True)[:nbytes]
        except ValueError:
            return None


def _check_block(h, a, src):
    """One array's data: its block header against the extent and the bytes the file holds."""
    hs = 8 if h.header_type == "UInt64" else 4
    fmt = ("<" if h.byte_order == "LittleEndian" else ">") + ("Q" if hs == 8 else "I")
    who = f"{h.path}: array {a.name!r} ({a.where})"
    if not h.compressor:
        head = src.read(hs)
        if head is None:
            raise Refused(f"{who}: its data block's header lies past the end of the file (truncated?)")
        (nbytes,) = struct.unpack(fmt, head)
        if nbytes != a.nbytes:
            raise Refused(f"{who}: its data block holds {nbytes} bytes; its extent needs {a.nbytes}")
        if hs + nbytes > src.available():
            raise Refused(f"{who}: needs {_mb(a.nbytes)}; the file holds {_mb(max(src.available() - hs, 0))} "
                          "from its start (truncated, or an extent the data does not have)")
        return
    head = src.read(3 * hs)
    if head is None:
        raise Refused(f"{who}: its compressed block header lies past the end of the file (truncated?)")
    nb, bs, last = struct.unpack(fmt[0] + fmt[1] * 3, head)
    if nb == 0:
        if a.nbytes:
            raise Refused(f"{who}: 0 compressed blocks for {_mb(a.nbytes)}")
        return
    if (3 + nb) * hs > src.available():
        raise Refused(f"{who}: its header claims {nb} compressed blocks; the file has room for "
                      f"{max(src.available() // hs - 3, 0)}")
    if bs == 0 or (nb > 1 and bs > a.nbytes) or last > bs:
        raise Refused(f"{who}: compressed block size {bs}, last block {last}: not blocks of {_mb(a.nbytes)}")
    total = (nb - 1) * bs + (last if last else bs)
    if total != a.nbytes:
        raise Refused(f"{who}: its {nb} compressed blocks hold {_mb(total)}; its extent needs {_mb(a.nbytes)}")
    table = src.read((3 + nb) * hs)
    if table is None:
        raise Refused(f"{who}: its compressed block table lies past the end of the file (truncated?)")
    sizes = struct.unpack(fmt[0] + fmt[1] * nb, table[3 * hs:])
    compressed = sum(sizes)
    if (3 + nb) * hs + compressed > src.available() + 4:
        raise Refused(f"{who}: its compressed blocks claim {_mb(compressed)}; the file holds "
                      f"{_mb(src.available())} from their start")
    ratio = RATIO.get(h.compressor)
    if ratio:
        full = min(sizes[:-1]) if nb > 1 else None
        for c, u in ((full, bs), (sizes[-1], last if last else bs)):
            if c is not None and u > ratio * max(c, 1) + 64:
                raise Refused(f"{who}: a compressed block of {c} bytes claims {_mb(u)}; "
                              f"{h.compressor} does not shrink data more than {ratio}:1")


def scan(path, max_bytes, copies=1, per_point=0):
    """Reads path's XML header and checks what it claims (see the module's doc): `copies` times the bytes
    of its arrays, plus `per_point` bytes for each point (the caller's own work), must fit in max_bytes.
    Returns the Header."""
    path = os.fspath(path)
    ext = Path(path).suffix.lower()
    if ext not in DATASETS:
        raise Refused(f"{path}: expected a VTK XML .vti, .vtr, .vts or .vtm file (a {ext or 'nameless'} file)")
    try:
        size = os.path.getsize(path)
        f = open(path, "rb")
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such file") from None
    with f:
        if size == 0:
            raise Refused(f"{path}: an empty file")
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mm:
            h = _parse(path, mm)
            if h.type == "vtkMultiBlockDataSet":
                return h
            _check_sizes(h, mm, max_bytes, copies, per_point)
    return h


def _check_sizes(h, mm, max_bytes, copies, per_point):
    path = h.path
    if not h.pieces:
        raise Refused(f"{path}: no <Piece> with an Extent: not a {h.type} VTK reads")
    if not h.whole_extent:
        raise Refused(f"{path}: <{h.type}> has no WholeExtent")
    for e in (h.whole_extent, *h.pieces):
        if any(e[2 * a + 1] < e[2 * a] for a in range(3)):
            raise Refused(f"{path}: an empty extent {' '.join(map(str, e))} (each max must be >= its min)")
    we = h.whole_extent
    for e in h.pieces:
        if any(e[2 * a] < we[2 * a] or e[2 * a + 1] > we[2 * a + 1] for a in range(3)):
            raise Refused(f"{path}: a piece's Extent {' '.join(map(str, e))} lies outside WholeExtent "
                          f"{' '.join(map(str, we))}")
    dims = [we[2 * a + 1] - we[2 * a] + 1 for a in range(3)]
    whole = dims[0] * dims[1] * dims[2]
    for a in h.arrays:
        e = h.pieces[a.piece] if 0 <= a.piece < len(h.pieces) else we
        if a.where in ("PointData", "Points"):
            a.tuples = _count(e, 0)
        elif a.where == "CellData":
            a.tuples = _count(e, 1)
        elif a.where == "Coordinates":
            i = a.ordinal
            a.tuples = e[2 * i + 1] - e[2 * i] + 1 if i < 3 else 0
        elif a.tuples < 0:
            a.tuples = 0
    # What VTK allocates: the whole extent for each point and cell array, the points or coordinates.
    need = max(sum(a.nbytes for a in h.arrays),
               whole * sum(a.components * TYPES[a.type] for a in h.arrays
                           if a.where in ("PointData", "Points") and a.piece == 0))
    h.need = need
    if need * copies + whole * per_point > max_bytes:
        raise Refused(f"{path}: claims {dims[0]}x{dims[1]}x{dims[2]} points whose arrays take {_mb(need)}"
                      + (f" (x{copies}: VTK's and the converter's copies)" if copies > 1 else "")
                      + (f" and their analysis {_mb(whole * per_point)}" if per_point else "")
                      + f"; over the memory limit of {_mb(max_bytes)} (--max-memory MB to allow more)")
    for a in h.arrays:
        if a.format == "appended":
            if not h.appended[0]:
                raise Refused(f"{path}: array {a.name!r} is appended but the file has no <AppendedData>")
            start = h.appended[0] + a.offset
            if start >= h.appended[1] and a.nbytes:
                raise Refused(f"{path}: array {a.name!r} starts at appended offset {a.offset}, past the "
                              f"appended data's {h.appended[1] - h.appended[0]} bytes")
            _check_block(h, a, _Source(mm, start, h.appended[1], h.encoding == "base64"))
        elif a.format == "binary":
            _check_block(h, a, _Source(mm, a.content[0], a.content[1], True))
        else:  # ascii: every value takes at least one character and a separator
            values = a.tuples * a.components
            text = a.content[1] - a.content[0]
            if values and 2 * values - 1 > text:
                raise Refused(f"{path}: array {a.name!r} needs {values} ASCII values; its text has {text} "
                              "characters")


def blocks(path):
    """The data sets a .vtm names: [(label, absolute file path)] in file order."""
    h = scan(path, 0)
    base = Path(path).resolve().parent
    return [(label, str((base / f))) for label, f in h.datasets]
