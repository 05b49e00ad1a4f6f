#!/usr/bin/env python3
"""Keeps the documentation honest: what the code and the docs cite must exist.

Checks, over the repository's sources (core, service, client, plot, proto, tests, bench,
examples, scripts, cmake, docs, README.md):

1. Every `*.md` path named exists (relative to the repository root, to the naming file's folder,
   or, for a bare file name, in docs/), and so does every local target of a Markdown link.
2. Every `§N.M` section named exists as a heading carrying that number (`## 3.`, `### 3.2 ...`)
   in the document named just before it (within a few lines); in a Markdown file a `§` with no
   document before it refers to the file itself. Outside Markdown a `§` must name its document.
3. No document outside the repository is cited (design-anchors, ../shared/...).
4. Every example file the docs name (examples/...) exists.
5. Every `seep <command>` written as code in docs/guide/ (and README.md, docs/reference/cli.md)
   is a command the CLI declares: the CLI11 subcommands of client/*.cc, read from the source, so
   no build is needed.
6. Every field of proto/seep/v1/scene.proto reachable from Scene has a row in docs/reference/:
   a table row starting with the field in backticks, under a heading naming its message.

Usage: check_docs.py [--root DIR] [--plant 'FILE|TEXT']
  --plant appends TEXT to FILE's content in memory (the file is not touched), to show that the
  check fails on a planted error. Prints each problem as `file: message`; exit 0 when there are
  none, 1 otherwise. Python 3, standard library only.
"""
import argparse
import collections
import os
import re
import sys

SCAN_DIRS = ["core", "service", "client", "plot", "proto", "tests", "bench", "examples", "scripts",
             "cmake", "docs"]
SCAN_FILES = ["README.md", "CMakeLists.txt"]
SCAN_EXTS = (".h", ".cc", ".cpp", ".proto", ".py", ".sh", ".md", ".textproto", ".cmake", ".txt",
             ".json")
SKIP_FILES = {"bench/settled_bed_9900.txt", "tests/docs/check_docs.py"}
# A line carrying this marker is not read (the planted test's own command line).
SKIP_LINE = "check_docs: skip"
OUTSIDE = re.compile(r"design-anchors|\.\./shared/|/work/shared|core-redesign\.md")

MD_PATH = re.compile(r"(?<![\w./-])((?:\.{1,2}/)*[\w][\w./-]*\.md)(?![\w-])")
SECTION = re.compile(r"§\s*([0-9]+(?:\.[0-9]+)*)")
MD_LINK = re.compile(r"\[([^\]]*)\]\(([^)\s]+)\)")
HEADING_NUMBER = re.compile(r"^#{1,6}\s+`?([0-9]+(?:\.[0-9]+)*)\.?[\s`]")
EXAMPLE = re.compile(r"(?<![\w/])examples/[\w.-]+\.(?:textproto|json)")
# A § belongs to the document named at most this many characters before it (in Markdown, where
# a § with no document before it means the file itself, a shorter reach).
WINDOW = 240
MD_WINDOW = 60


class Checker:
    def __init__(self, root, plants):
        self.root = root
        self.plants = plants  # path -> text appended in memory
        self.errors = []
        self.heading_cache = {}

    def error(self, where, message):
        self.errors.append(f"{where}: {message}")

    def read(self, rel):
        with open(os.path.join(self.root, rel), encoding="utf-8", errors="replace") as f:
            text = f.read()
        text = "\n".join("" if SKIP_LINE in line else line for line in text.split("\n"))
        return text + self.plants.get(rel, "")

    def files(self):
        out = [f for f in SCAN_FILES if os.path.exists(os.path.join(self.root, f))]
        for top in SCAN_DIRS:
            for folder, dirs, names in os.walk(os.path.join(self.root, top)):
                dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d != "build")
                for name in sorted(names):
                    rel = os.path.relpath(os.path.join(folder, name), self.root)
                    if rel in SKIP_FILES or not name.endswith(SCAN_EXTS):
                        continue
                    out.append(rel)
        for rel in self.plants:
            if rel not in out:
                out.append(rel)
        return out

    def resolve(self, rel_from, path):
        """The repository-relative path a document name refers to, or None."""
        path = path.split("#", 1)[0]
        candidates = [os.path.normpath(os.path.join(os.path.dirname(rel_from), path)),
                      os.path.normpath(path)]
        if "/" not in path:
            candidates.append(os.path.join("docs", path))
        for c in candidates:
            if not c.startswith("..") and os.path.exists(os.path.join(self.root, c)):
                return c
        return None

    def headings(self, rel):
        if rel not in self.heading_cache:
            numbers = set()
            in_code = False
            for line in self.read(rel).split("\n"):
                if line.startswith("```"):
                    in_code = not in_code
                    continue
                m = None if in_code else HEADING_NUMBER.match(line)
                if m:
                    numbers.add(m.group(1))
            self.heading_cache[rel] = numbers
        return self.heading_cache[rel]

    # 1-3: documents and sections
    def check_citations(self, rel, text):
        is_md = rel.endswith(".md")
        if OUTSIDE.search(text):
            for m in OUTSIDE.finditer(text):
                self.error(f"{rel}:{line_of(text, m.start())}",
                           f"cites '{m.group(0)}', which is outside the repository")
        scan = text
        if is_md:
            for m in MD_LINK.finditer(text):
                target = m.group(2)
                if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                    continue
                if self.resolve(rel, target) is None:
                    self.error(f"{rel}:{line_of(text, m.start())}",
                               f"link to '{target}', which does not exist")
            # Scan a link as its target alone: its text may name a document relatively to
            # another folder ([physics.md](../physics.md)).
            scan = MD_LINK.sub(lambda m: "`" + m.group(2) + "`", text)
        docs = []  # (position, resolved path or None, name)
        for m in MD_PATH.finditer(scan):
            name = m.group(1)
            if "*" in name or name.startswith("<"):
                continue
            target = self.resolve(rel, name)
            if target is None:
                self.error(f"{rel}:{line_of(scan, m.start())}",
                           f"names '{name}', which does not exist")
            docs.append((m.end(), target, name))
        for m in SECTION.finditer(scan):
            number = m.group(1)
            reach = MD_WINDOW if is_md else WINDOW
            before = [d for d in docs if d[0] <= m.start() and m.start() - d[0] <= reach]
            if before:
                _, target, name = before[-1]
                if target is None:
                    continue  # already reported
            elif is_md:
                target, name = rel, os.path.basename(rel)
            else:
                self.error(f"{rel}:{line_of(scan, m.start())}",
                           f"§{number} names no document (write docs/<doc>.md §{number})")
                continue
            if not target.endswith(".md"):
                continue
            if number not in self.headings(target):
                self.error(f"{rel}:{line_of(scan, m.start())}",
                           f"{name} §{number}: no heading numbered {number} in {target}")

    # 4: example scenes
    def check_examples(self, rel, text):
        for m in EXAMPLE.finditer(text):
            if not os.path.exists(os.path.join(self.root, m.group(0))):
                self.error(f"{rel}:{line_of(text, m.start())}",
                           f"names the example '{m.group(0)}', which is not in examples/")

    # 5: CLI commands
    def cli(self):
        top, nested, value_options = set(), collections.defaultdict(set), set()
        names = {}
        decl = re.compile(
            r"(?:auto\s*\*\s*)?([\w.]+)\s*=\s*([\w.]+)\s*(?:\.|->)\s*add_subcommand\(\s*\"([\w-]+)\"",
            re.S)
        for name in sorted(os.listdir(os.path.join(self.root, "client"))):
            if not name.endswith(".cc"):
                continue
            text = self.read(os.path.join("client", name))
            for var, receiver, command in decl.findall(text):
                names[var] = command
                names[var.split(".")[-1]] = command
                if receiver == "app":
                    top.add(command)
                else:
                    parent = names.get(receiver, names.get(receiver.split(".")[-1]))
                    nested[parent].add(command)
            if name == "main.cc":
                value_options.update(re.findall(r"app\.add_option\(\s*\"(--[\w-]+)\"", text))
        return top, nested, value_options

    def check_cli(self, rel, text, top, nested, value_options):
        code = []
        for m in re.finditer(r"```.*?\n(.*?)```", text, re.S):
            code.append((m.start(1), m.group(1)))
        without_blocks = re.sub(r"```.*?```", lambda m: " " * len(m.group(0)), text, flags=re.S)
        for m in re.finditer(r"`([^`\n]+)`", without_blocks):
            code.append((m.start(1), m.group(1)))
        for start, snippet in code:
            for line in snippet.split("\n"):
                for m in re.finditer(r"(?:^|[\s$(;&|])seep((?:\s+\S+)+)", line):
                    self.check_command(rel, line_of(text, start), m.group(1).split(), top,
                                       nested, value_options)

    def check_command(self, rel, line, tokens, top, nested, value_options):
        i = 0
        while i < len(tokens) and tokens[i].startswith("-"):
            option = tokens[i]
            i += 1
            if option in value_options and "=" not in option:
                i += 1
        if i >= len(tokens):
            return
        command = tokens[i].strip("`,.;:)")
        if not re.fullmatch(r"[a-z][a-z-]*", command):
            return  # a placeholder (<command>, ...) or not a command line
        if command not in top:
            self.error(f"{rel}:{line}", f"'seep {command}' is not a command of the CLI (client/)")
            return
        if command in nested and i + 1 < len(tokens):
            for sub in tokens[i + 1].replace("\\|", "|").strip("`,.;:)").split("|"):
                if re.fullmatch(r"[a-z][a-z-]*", sub) and sub not in nested[command]:
                    if command == "sweep" or tokens[i + 1].count("|"):
                        self.error(f"{rel}:{line}",
                                   f"'seep {command} {sub}' is not a command of the CLI")

    # 6: scene fields in docs/reference
    def check_scene_reference(self):
        proto = self.read("proto/seep/v1/scene.proto")
        messages = {}
        current, depth = None, 0
        for line in proto.split("\n"):
            code = line.split("//", 1)[0]
            m = re.match(r"\s*message\s+(\w+)\s*\{", code)
            if m and depth == 0:
                current = m.group(1)
                messages[current] = []
            elif current is not None and depth >= 1:
                f = re.match(r"\s*(?:optional\s+|repeated\s+)?([\w.]+)\s+(\w+)\s*=\s*\d+", code)
                if f and f.group(1) not in ("option", "reserved"):
                    messages[current].append((f.group(1), f.group(2)))
            depth += code.count("{") - code.count("}")
            if depth == 0:
                current = None
        reachable, todo = set(), ["Scene"]
        while todo:
            name = todo.pop()
            if name in reachable or name not in messages:
                continue
            reachable.add(name)
            todo.extend(t for t, _ in messages[name] if t in messages)
        documented = set()
        ref = os.path.join(self.root, "docs", "reference")
        for folder, _, names in os.walk(ref):
            for name in names:
                if not name.endswith(".md"):
                    continue
                rel = os.path.relpath(os.path.join(folder, name), self.root)
                heading_messages = []
                for line in self.read(rel).split("\n"):
                    if line.startswith("#"):
                        heading_messages = re.findall(r"`(\w+)`", line)
                        continue
                    row = re.match(r"\|\s*`(\w+)`\s*\|", line)
                    if row:
                        for message in heading_messages:
                            documented.add((message, row.group(1)))
        for message in sorted(reachable):
            for _, field in messages[message]:
                if (message, field) not in documented:
                    self.error("docs/reference",
                               f"scene.proto {message}.{field} has no row under a `{message}` "
                               "heading")
        return sum(len(messages[m]) for m in reachable)

    def run(self):
        top, nested, value_options = self.cli()
        if not top:
            self.error("client/", "found no CLI11 subcommand declarations")
        files = self.files()
        for rel in files:
            text = self.read(rel)
            self.check_citations(rel, text)
            if rel.startswith("docs/") or rel == "README.md":
                self.check_examples(rel, text)
            if rel.startswith("docs/guide/") or rel in ("README.md", "docs/reference/cli.md"):
                self.check_cli(rel, text, top, nested, value_options)
        fields = self.check_scene_reference()
        return len(files), len(top), fields


def line_of(text, position):
    return text.count("\n", 0, position) + 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), "..", ".."))
    parser.add_argument("--plant", action="append", default=[],
                        help="FILE|TEXT: append TEXT to FILE in memory")
    args = parser.parse_args()
    plants = {}
    for plant in args.plant:
        path, _, text = plant.partition("|")
        plants[path] = plants.get(path, "") + "\n" + text + "\n"
    checker = Checker(os.path.abspath(args.root), plants)
    files, commands, fields = checker.run()
    for e in checker.errors:
        print(e)
    if checker.errors:
        print(f"check_docs: {len(checker.errors)} problem(s) in {files} files")
        return 1
    print(f"check_docs: OK ({files} files; {commands} CLI commands; {fields} scene fields "
          "documented)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
