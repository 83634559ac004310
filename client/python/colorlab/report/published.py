"""The dissertation's published numbers (Ulbricht 2006), quoted as printed, each with where it stands.

Values are kept as the printed strings so that a unit test can find each one at its place in the text
(/work/shared/seed/ulbricht-2006-dissertation.txt: ``line`` is the 1-based line of that text, ``page`` the
page the dissertation's own list of tables/figures gives). Cells the text's OCR left illegible are None rather
than guessed: a guessed number would be a misquote.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Row:
    label: str
    line: int
    cells: tuple  # printed strings or None (illegible); field k of the tab-split line is cells[k - 1]

    def values(self) -> list:
        return [None if c is None else float(c) for c in self.cells]


@dataclass(frozen=True)
class Table:
    number: str        # "Table 2"
    title: str
    section: str
    page: int
    columns: tuple
    rows: tuple
    unit: str = ""

    def row(self, label: str) -> Row:
        return next(r for r in self.rows if r.label == label)

    def ref(self) -> str:
        return f"{self.number}, §{self.section}, p. {self.page} (text lines {self.rows[0].line}–{self.rows[-1].line})"


@dataclass(frozen=True)
class Scalar:
    label: str
    text: str          # as printed
    line: int
    page: int
    item: str          # the figure or passage it belongs to

    @property
    def value(self) -> float:
        return float(self.text)

    def ref(self) -> str:
        return f"{self.item}, p. {self.page} (text line {self.line})"


def _row(label, line, *cells):
    return Row(label, line, tuple(cells))


TABLE2 = Table(
    "Table 2", "Median and mean of the standard deviations of all 140 patches against frames averaged", "6.1.3", 54,
    ("1", "2", "4", "8", "16", "25"),
    (_row("R median", 949, "1.08", "0.85", "0.70", "0.62", "0.56", "0.55"),
     _row("G median", 950, "0.95", "0.77", "0.66", "0.59", "0.55", "0.54"),
     _row("B median", 951, "1.18", "0.92", "0.75", "0.65", "0.59", "0.56"),
     _row("R mean", 952, "1.21", "0.97", "0.78", "0.68", "0.61", "0.58"),
     _row("G mean", 953, "0.97", "0.81", "0.68", "0.62", "0.58", "0.57"),
     _row("B mean", 954, "1.19", "0.95", "0.78", "0.68", "0.62", "0.59")),
    unit="camera counts")

_J = tuple(str(j) for j in range(16))
_N = None

# Tables 3-6: standard deviation of every 4x5 window of the mirrored 8x20 D65 luminance-difference grid.
WINDOW_TABLES = {
    100: Table("Table 3", "Standard deviation of all 80 submatrices, D65, dimmer 100 %", "6.2", 60, _J, (
        _row("0", 1012, "26.16", "24.57", "23.32", "19.84", "16.31", "14.74", "13.69", "11.59", "11.59", "13.69", "14.74", "16.31", "19.84", "23.32", "24.57", "26.16"),
        _row("1", 1013, "25.12", "23.67", "22.08", "18.92", "16.05", "14.10", "12.97", "13.37", "13.37", "12.97", "14.10", "16.05", "18.92", "22.08", "23.67", "25.12"),
        _row("2", 1014, "25.53", "23.76", "21.06", "17.64", "14.77", "12.51", "11.19", "12.93", "12.93", "11.19", "12.51", "14.77", "17.64", "21.06", "23.76", "25.53"),
        _row("3", 1015, "24.76", "22.90", "19.73", "16.26", "14.02", "11.61", "9.52", "10.06", "10.06", "9.52", "11.61", "14.02", "16.26", "19.73", "22.90", "24.76"),
        _row("4", 1016, "25.63", "23.80", "19.67", "16.35", "14.17", "11.43", "9.12", "6.28", "6.28", "9.12", "11.43", "14.17", "16.35", "19.67", "23.80", "25.63")),
        unit="cd/m²"),
    50: Table("Table 4", "Standard deviation of all 80 submatrices, D65, dimmer 50 %", "6.2", 61, _J, (
        _row("0", 1025, "13.15", "12.40", "11.77", "11.18", "9.88", "8.80", "7.90", "7.92", "7.92", "7.90", "8.80", "9.88", "11.18", "11.77", "12.40", "13.15"),
        _row("1", 1026, "13.16", "12.13", "10.96", "10.00", "8.44", "7.09", "5.75", "5.60", "5.60", "5.75", "7.09", "8.44", "10.00", "10.96", "12.13", "13.16"),
        _row("2", 1027, "13.00", "11.72", "10.44", "9.21", "7.27", "6.00", "4.43", "4.23", "4.23", "4.43", "6.00", "7.27", "9.21", "10.44", "11.72", "13.00"),
        _row("3", 1028, "12.57", "11.26", "9.62", "8.55", "6.84", "5.26", "3.22", "1.61", "1.61", "3.22", "5.26", "6.84", "8.55", "9.62", "11.26", "12.57"),
        _row("4", 1029, "12.85", "11.30", "9.52", "8.64", "6.91", "5.61", "3.84", "1.98", "1.98", "3.84", "5.61", "6.91", "8.64", "9.52", "11.30", "12.85")),
        unit="cd/m²"),
    # Row 0 is partly garbled in the text (only cells whose mirror image agrees are kept); row 1 is illegible.
    25: Table("Table 5", "Standard deviation of all 80 submatrices, D65, dimmer 25 %", "6.2", 61, _J, (
        _row("0", 1034, "5.79", "5.30", _N, _N, _N, "3.74", "3.31", "3.05", "3.05", "3.31", "3.74", _N, _N, _N, "5.30", "5.79"),
        _row("1", 1036, *([_N] * 16)),
        _row("2", 1037, "5.55", "4.98", "4.64", "4.68", "4.14", "3.29", "2.30", "1.71", "1.71", "2.30", "3.29", "4.14", "4.68", "4.64", "4.98", "5.55"),
        _row("3", 1038, "5.49", "4.90", "4.61", "4.53", "3.88", "3.04", "1.89", "1.12", "1.12", "1.89", "3.04", "3.88", "4.53", "4.61", "4.90", "5.49"),
        _row("4", 1039, "5.74", "5.21", "4.91", "4.59", "3.67", "2.77", "1.67", "1.15", "1.15", "1.67", "2.77", "3.67", "4.59", "4.91", "5.21", "5.74")),
        unit="cd/m²"),
    # Rows 1 and 2 are illegible in the text, and row 3's two minima are printed reversed ("96.0").
    15: Table("Table 6", "Standard deviation of all 80 submatrices, D65, dimmer 15 %", "6.2", 61, _J, (
        _row("0", 1044, "3.31", "3.23", "3.12", "3.04", "2.54", "2.32", "2.10", "1.77", "1.77", "2.10", "2.32", "2.54", "3.04", "3.12", "3.23", "3.31"),
        _row("1", 1046, *([_N] * 16)),
        _row("2", 1047, *([_N] * 16)),
        _row("3", 1048, "3.34", "3.02", "2.87", "2.58", "2.12", "1.68", "1.18", _N, _N, "1.18", "1.68", "2.12", "2.58", "2.87", "3.02", "3.34"),
        _row("4", 1049, "3.55", "3.13", "2.92", "2.42", "2.15", "1.67", "1.17", "0.96", "0.96", "1.17", "1.67", "2.15", "2.42", "2.92", "3.13", "3.55")),
        unit="cd/m²"),
}

# §6.2's numbers in the running text; ``page`` is that of the figure or table named in ``item``.
D65_MIN = Scalar("D65 100 % minimum luminance", "173.20", 974, 56, "§6.2, fig. 36")
D65_MAX = Scalar("D65 100 % maximum luminance", "319.90", 974, 56, "§6.2, fig. 36")
D65_RANGE = Scalar("D65 100 % maximum difference", "146.70", 974, 56, "§6.2, fig. 36")
D65_15_RANGE = Scalar("D65 15 % maximum difference", "19.75", 989, 58, "§6.2, fig. 38")
DIMMER_MAX_ABS_ERROR = {  # D65, level -> max |100 % - level scaled by 100/level|
    50: Scalar("D65 50 % scaled, max abs error", "17.92", 991, 58, "§6.2, fig. 39"),
    25: Scalar("D65 25 % scaled, max abs error", "24.58", 991, 59, "§6.2, fig. 40"),
    15: Scalar("D65 15 % scaled, max abs error", "25.07", 991, 59, "§6.2, fig. 41"),
}
BEST_WINDOW_STDEV = {  # D65, level -> smallest window standard deviation
    100: Scalar("D65 100 % best window", "6.28", 1020, 60, "§6.2, Tables 3-6"),
    50: Scalar("D65 50 % best window", "1.61", 1020, 60, "§6.2, Tables 3-6"),
    25: Scalar("D65 25 % best window", "1.12", 1020, 60, "§6.2, Tables 3-6"),
    15: Scalar("D65 15 % best window", "0.96", 1020, 60, "§6.2, Tables 3-6"),
}
WORST_WINDOW_STDEV = {  # lamp at 100 % -> largest window standard deviation; 840 is the lab's TL84
    "D65": Scalar("D65 largest window stdev", "26.16", 1022, 60, "§6.2, figs. 42, 45, 46"),
    "TL84": Scalar("840 largest window stdev", "40.39", 1022, 64, "§6.2, fig. 45"),
    "CWF": Scalar("CWF largest window stdev", "40.30", 1022, 65, "§6.2, fig. 46"),
}

_STATS = ("Min", "Max", "Median", "Mean", "Stdev")


def _stats_table(number, title, section, page, columns, first_line, rows, unit="ΔE*ab"):
    return Table(number, title, section, page, columns,
                 tuple(_row(label, first_line + k, *cells) for k, (label, cells) in enumerate(zip(_STATS, rows))),
                 unit=unit)


# Chapter 7: ΔE*ab statistics over the 140 patches; columns are the test cases (Tables 9, 10) or the
# polynomials of §7.3 (Tables 11, 12, on the 8-bit TIFF).
TABLE9 = _stats_table("Table 9", "ΔE*ab using the camera's colour space", "7.1", 71, ("tiff8", "jpeg", "tiff16"), 1159, (
    ("2.77", "2.28", "1.85"), ("29.21", "29.26", "29.39"), ("12.32", "12.32", "12.34"), ("13.30", "13.31", "13.33"),
    ("5.87", "5.94", "5.91")))
TABLE10 = _stats_table("Table 10", "ΔE*ab using an ICC profile", "7.2", 74, ("tiff8", "jpeg", "tiff16"), 1198, (
    ("4.05", "3.82", "3.65"), ("20.96", "20.95", "20.69"), ("11.24", "11.30", "11.21"), ("12.25", "12.23", "12.20"),
    ("4.33", "4.35", "4.33")))
TABLE11 = _stats_table("Table 11", "ΔE*ab of the adapted mapping, linear polynomials 1-4 (8-bit TIFF)", "7.3", 79,
                       ("1", "2", "3", "4"), 1265, (
    ("1.44", "0.55", "1.70", "0.41"), ("21.90", "22.33", "17.81", "17.42"), ("6.64", "5.80", "5.30", "4.92"),
    ("7.63", "6.99", "6.26", "5.68"), ("4.60", "5.01", "3.64", "3.86")))
TABLE12 = _stats_table("Table 12", "ΔE*ab of the adapted mapping, higher-order polynomials 5-11 (8-bit TIFF)", "7.3", 81,
                       ("5", "6", "7", "8", "9", "10", "11"), 1278, (
    ("0.50", "0.49", "0.13", "0.26", "0.32", "0.13", "0.08"), ("15.84", "14.97", "9.67", "8.92", "8.73", "5.67", "7.68"),
    ("3.87", "3.00", "2.42", "2.28", "2.42", "1.86", "2.14"), ("4.50", "3.93", "2.89", "2.56", "2.79", "2.13", "2.64"),
    ("2.65", "2.81", "1.69", "1.45", "1.65", "1.16", "1.64")))
# Table 13: black-box residuals in 12-bit RAW counts (0-4095); the printed relative errors are left out.
TABLE13 = _stats_table("Table 13", "Black-box residuals of R, G, B against the RAW image", "7.4", 84, ("R", "G", "B"), 1322, (
    ("0.81", "0.36", "0.15"), ("193.93", "295.46", "167.69"), ("57.44", "51.70", "46.30"), ("65.57", "63.98", "52.99"),
    ("45.24", "51.31", "40.77")), unit="RAW counts (0-4095)")

# §6.2's end, "which dimmer setting to use": one photograph per dimmer level, the exposure doubled as the light
# halves (Table 7; exposure times printed as fractions of a second), and the interval length (max - min) of R, G, B
# over the SG's 14 dark border patches (Table 8; 8-bit values). The text's B row label is a Cyrillic "В".
TABLE7 = Table("Table 7", "Camera settings at 100 %, 50 %, 25 % and 15 %", "6.2", 68, ("100", "50", "25", "15"), (
    _row("Aperture", 1110, "4.0", "4.0", "4.0", "4.0"),
    _row("Exposure time", 1111, "1/30", "1/15", "1/8", "1/4")), unit="f-number, s")
TABLE8 = Table("Table 8", "Interval length of R, G and B values of the dark border patches at 100 %, 50 %, 25 % and 15 %",
               "6.2", 68, ("100", "50", "25", "15"), (
    _row("R", 1116, "14.06", "14.53", "15.57", "19.35"),
    _row("G", 1117, "13.61", "14.56", "14.86", "17.79"),
    _row("B", 1118, "14.16", "14.77", "15.62", "18.62")), unit="8-bit values")


def seconds(printed: str) -> float:
    """An exposure time as Table 7 prints it ("1/30") in seconds."""
    num, _, den = printed.partition("/")
    return float(num) / float(den) if den else float(num)


ALL_TABLES = (TABLE2, *WINDOW_TABLES.values(), TABLE7, TABLE8, TABLE9, TABLE10, TABLE11, TABLE12, TABLE13)
ALL_SCALARS = (D65_MIN, D65_MAX, D65_RANGE, D65_15_RANGE, *DIMMER_MAX_ABS_ERROR.values(),
               *BEST_WINDOW_STDEV.values(), *WORST_WINDOW_STDEV.values())
