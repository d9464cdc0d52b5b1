#!/usr/bin/env python3
"""Extracts the tour of docs/python.md (every ```python block, in order) into one script, so
scripts/python.sh can type-check it with mypy --strict and run it: the documentation's code is
tested code.

Usage: python3 scripts/python_tour.py docs/python.md OUT.py
"""

import re
import sys


def main() -> None:
    src, out = sys.argv[1], sys.argv[2]
    text = open(src, encoding="utf-8").read()
    blocks = re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)
    if not blocks:
        sys.exit(f"{src}: no ```python blocks")
    with open(out, "w", encoding="utf-8") as f:
        f.write(f'"""The tour of {src} ({len(blocks)} blocks), extracted by scripts/python_tour.py."""\n')
        for i, b in enumerate(blocks):
            f.write(f"\n# --- block {i + 1}\n{b}")
    print(f"{out}: {len(blocks)} blocks from {src}")


if __name__ == "__main__":
    main()
