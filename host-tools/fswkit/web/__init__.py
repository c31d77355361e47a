"""The web ground station: a Starlette (ASGI) application served by uvicorn
that shows a live link in a browser (plots drawn with uPlot, the state
timeline, link health, the task table) and sends commands through the same
serialised path as every other ground client. docs/ground.md."""
