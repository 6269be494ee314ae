"""``python -m uvnav``: same as the ``uvnav`` console script."""

from uvnav.cli.app import main

if __name__ == "__main__":
    main()
