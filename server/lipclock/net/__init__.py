"""The only I/O layer: FastAPI app, WebSocket protocol, channels, clocks."""
