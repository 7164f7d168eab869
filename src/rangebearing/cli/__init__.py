"""The ``rangebearing`` command line: thin handlers over the library."""
