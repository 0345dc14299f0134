"""``python -m fieldkit`` runs the command line."""

from fieldkit.cli import main

if __name__ == "__main__":
    main()
