"""The flight report's parts: the images drawn with matplotlib and the one-page HTML summary."""
