"""The generated parts of the docs: text between <!-- NAME:begin --> and <!-- NAME:end --> markers,
rewritten by the scripts that measure it (bench-doc.sh, fidelity-doc.sh)."""

import os
import sys


def paste_between_markers(text, name, body):
    """text with the part between NAME's markers replaced by body; None when a marker is missing."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    if begin not in text or end not in text:
        return None
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return head + begin + "\n" + body + end + tail


def update_doc(path, name, body, tool):
    """Writes body between NAME's markers in the file at path, or prints it when the file lacks them."""
    text = open(path).read() if os.path.exists(path) else ""
    pasted = paste_between_markers(text, name, body)
    if pasted is None:
        print(body)
        print(f"{tool}: {path} has no <!-- {name}:begin --> ... <!-- {name}:end -->; printed the table instead",
              file=sys.stderr)
        return False
    open(path, "w").write(pasted)
    return True
