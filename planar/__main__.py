import sys

try:
    from planar.cli.main import main
except KeyboardInterrupt:  # Ctrl-C while importing
    print("planar: interrupted (no output written)", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
