"""The toolkit for shell scripts: PYTHONPATH=scripts /usr/bin/python3 -m candela_tools COMMAND ...

  digest IMAGE...                     one line per image: the digest of its pixels (image_digest), then its path
  record KEY FIGURE COMMAND HOST      set target KEY's figure in docs/figures/results.json (record_result)
"""
import sys

import candela_tools as ct


def main(argv):
    if len(argv) >= 2 and argv[0] == "digest":
        for path in argv[1:]:
            print("%s  %s" % (ct.image_digest(path), path))
        return 0
    if len(argv) == 5 and argv[0] == "record":
        ct.record_result(*argv[1:])
        return 0
    print(__doc__.strip(), file=sys.stderr)
    return 2


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except ct.UserError as e:
        ct.fail(str(e))
