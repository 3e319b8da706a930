"""The package's user-error type, in the base layer so every layer can raise it."""


class ConfigError(ValueError):
    """A configuration value is missing, of the wrong type or out of range; the message
    holds one line per problem, each naming its key (or file, or flag)."""
