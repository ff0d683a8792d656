"""Errors the command line turns into one line on stderr and exit status 2."""


class InputError(ValueError):
    """Bad user input: a missing or malformed file, a value out of range, an unknown key.

    The message must name the file, key or value; it is printed as is, without a traceback.
    """
