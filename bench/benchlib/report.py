"""Markdown tables."""


def table(header: list, rows: list, align: str = "") -> str:
    """A markdown table; `align` has one 'l' or 'r' per column (default: first left)."""
    align = align or "l" + "r" * (len(header) - 1)
    sep = ["---:" if a == "r" else "---" for a in align]
    lines = [header, sep] + [[str(c) for c in r] for r in rows]
    return "\n".join("| " + " | ".join(r) + " |" for r in lines)


def fmt(x: float, digits: int = 2) -> str:
    return f"{x:.{digits}f}"


def fmt_rgb(v, digits: int = 4) -> str:
    return ", ".join(f"{c:.{digits}f}" for c in v)
