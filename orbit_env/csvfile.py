"""The user's CSV files as the user sees them: physical line numbers, an Excel BOM, binary files named.

Every CSV reader of the package (batch catalogues, observed orbits, solar tables)
reads through `read_csv`, so their errors say the same things the same way:

* every message starts with the file, and with the line when one line is at fault
  (``sats.csv, line 4: ...``), counting physical lines as an editor does: the header
  is line 1 and blank lines count;
* a header written by Excel ("CSV UTF-8") starts with a byte-order mark; it is read;
* a file that is not text (a spreadsheet saved as ``.xlsx``, an image) is refused by
  name, not with a decoding error.

Blank lines are skipped. A row with more cells than the header has columns keeps
its extra cells in `Row.extra`; the caller decides (a batch reports the row,
a solar table refuses the file). Trailing empty cells (``300,400,,``) are not extra.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["CsvTable", "Row", "read_csv"]


@dataclass(frozen=True)
class Row:
    """One data row: its physical line (1 = the header), cells by lower-case column name, extra cells."""

    line: int
    cells: dict[str, str]
    extra: list[str] = field(default_factory=list)

    def where(self, source: str) -> str:
        """``file, line N`` for messages."""
        return f"{source}, line {self.line}"


@dataclass(frozen=True)
class CsvTable:
    """A CSV file: its name (for messages), its header (lower case, stripped) and its data rows."""

    source: str
    header: list[str]
    rows: list[Row]

    def require(self, *columns: str, what: str) -> None:
        """Refuse a file without ``columns``, naming the file, the column and the header found.

        Args:
            columns: Required column names (lower case).
            what: What the file is, for the message (``"the batch file"``).
        """
        for column in columns:
            if column not in self.header:
                found = ", ".join(self.header) or "nothing"
                raise ValueError(f"{self.source}: {what} needs the '{column}' column; its header has {found}")


def cell_value(text: str) -> float | str:
    """A cell as a float, or the text itself (which ``check_number`` then refuses by name)."""
    try:
        return float(text)
    except ValueError:
        return text if text else "(empty)"


def read_csv(path: str | Path) -> CsvTable:
    """Read a CSV file with a header row (see the module docstring).

    Raises:
        ValueError: the file is not text, is empty, has no header, repeats a column,
            or is not CSV at some line (the message names the file and the line).
        OSError: the file cannot be opened.
    """
    source = str(path)
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            text = handle.read()
    except UnicodeDecodeError as error:
        raise ValueError(
            f"{source}: not a text CSV file (byte {error.object[error.start]:#04x} at offset {error.start} is not "
            "UTF-8; a spreadsheet must be saved as CSV)"
        ) from None
    except IsADirectoryError:
        raise ValueError(f"{source}: is a directory, not a CSV file") from None
    if "\x00" in text:
        line = text.count("\n", 0, text.index("\x00")) + 1
        raise ValueError(f"{source}, line {line}: not a text CSV file (it holds NUL bytes; a binary file?)")
    reader = csv.reader(io.StringIO(text, newline=""))
    header: list[str] | None = None
    rows: list[Row] = []
    try:
        while True:
            start = reader.line_num + 1
            try:
                cells = next(reader)
            except StopIteration:
                break
            if not any(cell.strip() for cell in cells):
                continue  # a blank line (or only commas)
            if header is None:
                header = [cell.strip().lower() for cell in cells]
                while header and header[-1] == "":
                    header.pop()
                repeated = sorted({name for name in header if name and header.count(name) > 1})
                if repeated:
                    raise ValueError(f"{source}, line {start}: the header repeats the column {repeated[0]!r}")
                continue
            values = [cell.strip() for cell in cells]
            extra = values[len(header) :]
            while extra and extra[-1] == "":
                extra.pop()
            named = {name: (values[k] if k < len(values) else "") for k, name in enumerate(header) if name}
            rows.append(Row(start, named, extra))
    except csv.Error as error:
        raise ValueError(f"{source}, line {reader.line_num}: not readable as CSV ({error})") from None
    if header is None:
        raise ValueError(f"{source}: the file is empty; expected a header row, then one row per line")
    return CsvTable(source, header, rows)
