"""Timeline -> mouth motion (visemes, node trajectories). Pure: no clocks, sockets or asyncio."""
