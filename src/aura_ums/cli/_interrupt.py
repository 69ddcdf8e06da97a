"""What a Ctrl-C ends the command line with: one definition, read before anything else loads."""

#: Exit code after a Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED = 130

#: The message when a Ctrl-C comes before anything was written.
NOTHING_WRITTEN = "interrupted: nothing was written"
