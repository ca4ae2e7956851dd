"""lipclock: text-to-speech with a talking face, stamped on the audio clock."""

__version__ = "0.1.0"
