"""The exit statuses of every ``symkin`` command, defined once."""

EXIT_OK = 0  # success (also with flagged points, which are warned about)
EXIT_FAILED = 1  # a solve or a check failed; what was solved is still written
EXIT_BAD_INPUT = 2  # bad input: a located one-paragraph message, never a traceback
EXIT_INTERRUPTED = 130  # SIGINT
