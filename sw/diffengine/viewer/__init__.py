"""The interactive viewer (`make view`, docs/viewer.md): `engine` (the scene held in a
`yproc serve` process, the golden model on each frame's changed lines, undo/redo, coarse
frames while dragging), `server` (`diffengine view`: aiohttp page + WebSocket on
127.0.0.1, the background RTL check) and `page.html`. The latency benchmark is
bench/viewer.py."""
