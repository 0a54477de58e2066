"""Sections of a generated document, each owned by one script.

docs/results.md is written by several scripts (compare, plot, and the scripts of later studies).
Each owns a section between two marker lines and replaces only that, so they can run in any
order and never clobber each other's tables:

    <!-- section NAME (scripts/OWNER): generated, do not edit by hand -->
    ...
    <!-- end section NAME -->

write_section() replaces the section's body, or adds the section at the end (or before the
section named `before`) when the document does not have it yet. Python standard library only.
"""
import os
import re


def _markers(name):
    begin = re.compile(r"^<!-- section %s \(.*?\): generated, do not edit by hand -->$" % re.escape(name), re.M)
    end = re.compile(r"^<!-- end section %s -->$" % re.escape(name), re.M)
    return begin, end


def write_section(path, name, owner, body, title="# Results", before=None):
    """Writes `body` (markdown) as section `name` of the document at `path`, atomically."""
    text = open(path).read() if os.path.exists(path) else title + "\n"
    block = "<!-- section %s (%s): generated, do not edit by hand -->\n%s\n<!-- end section %s -->\n" % (
        name, owner, body.strip("\n"), name)
    begin, end = _markers(name)
    b, e = begin.search(text), end.search(text)
    if b and e and e.start() > b.start():
        text = text[:b.start()] + block + text[e.end() + 1:]
    else:
        at = len(text)
        if before:
            nb, _ = _markers(before)
            hit = nb.search(text)
            if hit:
                at = hit.start()
        head = text[:at].rstrip("\n") + "\n\n"
        text = head + block + ("\n" + text[at:] if at < len(text) else "")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)
