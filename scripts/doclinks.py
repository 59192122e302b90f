#!/usr/bin/env python3
"""Relative links of the book (docs/*.md) and of README.md and BENCHMARKS.md: every linked file
exists and every `#anchor` into a Markdown file names one of its headings (mdBook's and GitHub's
slugs: lower case, spaces to `-`, other punctuation dropped). Standard library only.

    python3 scripts/doclinks.py      # exit 1, listing the broken links, if any
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def unfenced(text: str) -> str:
    return re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)


def prose(text: str) -> str:
    """The text without fenced code blocks and inline code."""
    return re.sub(r"`[^`\n]*`", "", unfenced(text))


def anchors(path: Path) -> set[str]:
    seen: dict[str, int] = {}
    out = set()
    for line in unfenced(path.read_text()).splitlines():
        m = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        slug = re.sub(r"[^\w\- ]", "", m.group(1).replace("`", "").lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


def main() -> int:
    files = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md", ROOT / "BENCHMARKS.md"]
    broken = []
    for f in files:
        if not f.is_file():
            continue
        for target in LINK.findall(prose(f.read_text())):
            if re.match(r"[a-z]+:", target):
                continue  # http:, https:, mailto:
            path, _, anchor = target.partition("#")
            dest = (f.parent / path).resolve() if path else f
            where = f.relative_to(ROOT)
            if not dest.exists():
                broken.append(f"{where}: {target}: no such file")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{where}: {target}: no heading with that anchor")
    for b in broken:
        print(b, file=sys.stderr)
    if broken:
        print(f"{len(broken)} broken link(s) in the docs", file=sys.stderr)
        return 1
    print(f"doc links ok ({len(files)} files)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
