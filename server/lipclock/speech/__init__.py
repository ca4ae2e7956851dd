"""Text -> Timeline -> audio. Pure: no clocks, sockets or asyncio in this package."""
