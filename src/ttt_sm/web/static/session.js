// The pages' link to the one running session: a WebSocket, commands out, frames in.
//
// A page is a view: it sends commands ({type, ...fields}, checked by the server's
// ttt_sm.web.protocol) and draws what comes back: "session" (what runs, once),
// "frame" (the state now and the transitions since the last frame; one "full"
// frame first), "reply" and "error" (to a command), "coverage".  Nothing here
// decides anything about the robot.  What every page draws alike (its header, the
// Safety chart) is page.js.

export class SessionLink {
  constructor(onMessage, onStatus) {
    this.onMessage = onMessage;
    this.onStatus = onStatus || (() => {});
    this.nextId = 1;
    this.ws = null;
    this.closedByPage = false;
  }

  connect() {
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    const ws = new WebSocket(`${scheme}//${location.host}/ws`);
    this.ws = ws;
    ws.onopen = () => {
      this.onStatus("connected");
      this.send({ type: "hello", page: document.body.dataset.page || "charts" });
    };
    ws.onmessage = (event) => {
      let message;
      try {
        message = JSON.parse(event.data);
      } catch (err) {
        this.onStatus(`unreadable message from the session: ${err}`);
        return;
      }
      this.onMessage(message);
    };
    ws.onclose = () => {
      this.onStatus("disconnected: the session is gone (stopped with Ctrl-C?); retrying ...");
      if (!this.closedByPage) setTimeout(() => this.connect(), 2000);
    };
  }

  // Send a command; returns its id (echoed in the reply or error).
  send(command) {
    const id = this.nextId++;
    if (this.ws && this.ws.readyState === WebSocket.OPEN) {
      this.ws.send(JSON.stringify({ ...command, id }));
    }
    return id;
  }

  // The page has drawn frame `seq` (its transitions highlighted): the latency figure.
  ack(seq) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) {
      this.ws.send(JSON.stringify({ type: "ack", frame: seq }));
    }
  }
}
