"""Allow ``python -m sailroute``."""

from sailroute.cli import main

if __name__ == "__main__":
    main()
