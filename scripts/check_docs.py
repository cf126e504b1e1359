#!/usr/bin/env python3
"""Checks the README and the guide, offline:
- the README stays a front page (at most 150 lines) and docs/measurements.md a reference (at most
  1,000 lines);
- every relative link of the README and the guide (docs/*.md and the other
Markdown files of the repository): the file it points to exists, and an anchor (#section) names a
heading of that file, spelled as GitHub spells heading anchors. Links to the web are left alone.
Exit code 1, naming each file too long and each broken link by file and line."""
import pathlib
import re
import subprocess
import sys
import urllib.parse

ROOT = pathlib.Path(__file__).resolve().parent.parent
LINK = re.compile(r"(?<!\!)\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)|!\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: markup dropped, lower case, punctuation but - and _ dropped,
    spaces turned into -."""
    text = re.sub(r"`([^`]*)`", r"\1", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = text.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: pathlib.Path) -> set:
    found, seen, fenced = set(), {}, False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        match = None if fenced else HEADING.match(line)
        if match:
            base = slug(match.group(2))
            count = seen.get(base, 0)
            seen[base] = count + 1
            found.add(base if count == 0 else f"{base}-{count}")
    return found


def markdown_files() -> list:
    listed = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard", "*.md"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    ).stdout.split()
    return [ROOT / name for name in listed if (ROOT / name).exists()]


LIMITS = {"README.md": 150, "docs/measurements.md": 1000}


def main() -> int:
    broken, checked = [], 0
    for name, limit in LIMITS.items():
        count = len((ROOT / name).read_text(encoding="utf-8").splitlines())
        if count > limit:
            broken.append(f"{name}: {count} lines, more than {limit}")
    for path in markdown_files():
        fenced = False
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if line.lstrip().startswith("```"):
                fenced = not fenced
                continue
            if fenced:
                continue
            line = re.sub(r"`[^`]*`", "", line)
            for match in LINK.finditer(line):
                target = match.group(1) or match.group(2)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target):
                    continue  # https:, mailto: and the like
                checked += 1
                file_part, _, anchor = target.partition("#")
                file_part = urllib.parse.unquote(file_part)
                dest = path if not file_part else (path.parent / file_part).resolve()
                where = f"{path.relative_to(ROOT)}:{number}"
                if not dest.exists():
                    broken.append(f"{where}: {target}: no such file")
                elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                    broken.append(f"{where}: {target}: no heading with the anchor #{anchor}")
    for line in broken:
        print(f"check_docs: {line}", file=sys.stderr)
    print(f"check_docs: {checked} relative links checked, {len(broken)} broken")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
