"""Config front end: lexer, parsers, checker and the typed model."""
