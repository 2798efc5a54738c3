// The live view of a running robokudo: a rosbridge v2 client written for this page (no library, no build step).
// It subscribes to the tree status, belief changes and camera topics, sends goals of the query action and cancels
// them, and reconnects when the server goes away.
"use strict";

const ACTION = "/robokudo/query";
const ACTION_TYPE = "robokudo_msgs/action/Query";
const TOPICS = [
  ["/robokudo/tree_status", "std_msgs/String"],
  ["/robokudo/beliefs", "std_msgs/String"],
  ["/robokudo/image", "robokudo_msgs/AnnotatedImage"],
  ["/robokudo/depth", "robokudo_msgs/AnnotatedImage"],
];
const GOAL_STATUS = { 4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED" };
const RECONNECT_MS = 1000;

const token = new URLSearchParams(window.location.search).get("token");
const view = {
  connection: document.getElementById("connection"),
  tick: document.getElementById("tick"),
  tree: document.getElementById("tree"),
  lastTask: document.getElementById("last-task"),
  details: document.getElementById("node-details"),
  colorFrame: document.getElementById("color-frame"),
  colorImage: document.getElementById("color-image"),
  depthImage: document.getElementById("depth-image"),
  boxes: document.getElementById("boxes"),
  frameKind: document.getElementById("frame-kind"),
  goals: document.querySelector("#goals tbody"),
  beliefs: document.querySelector("#beliefs tbody"),
  form: document.getElementById("query-form"),
  query: document.getElementById("query"),
};

let socket = null;
let requests = 0;
let shownShape = "";
let lastTaskShape = "";
const goals = new Map();
const beliefs = new Map();

function nextId(prefix) {
  requests += 1;
  return `${prefix}-${Date.now()}-${requests}`;
}

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) {
    socket.send(JSON.stringify(message));
    return true;
  }
  return false;
}

function setConnection(state, text) {
  view.connection.className = `state-${state}`;
  view.connection.dataset.state = state;
  view.connection.textContent = text;
}

function connect() {
  const scheme = window.location.protocol === "https:" ? "wss" : "ws";
  socket = new WebSocket(`${scheme}://${window.location.host}/`);
  setConnection("connecting", "connecting…");
  socket.onopen = () => {
    if (token) {
      send({ op: "auth", mac: token, client: "", dest: "", rand: "", t: 0, level: "", end: 0 });
    }
    for (const [topic, type] of TOPICS) {
      send({ op: "subscribe", id: nextId("sub"), topic, type });
    }
    send({ op: "call_service", id: nextId("beliefs"), service: "/robokudo/beliefs", args: { query: "find objects" } });
    setConnection("connected", "connected");
  };
  socket.onmessage = (event) => receive(JSON.parse(event.data));
  socket.onclose = () => {
    setConnection("disconnected", "disconnected — reconnecting…");
    socket = null;
    window.setTimeout(connect, RECONNECT_MS);
  };
}

function receive(message) {
  switch (message.op) {
    case "publish":
      published(message.topic, message.msg);
      break;
    case "action_feedback":
      goalFeedback(message.id, message.values);
      break;
    case "action_result":
      goalResult(message.id, message.status, message.values, message.result);
      break;
    case "service_response":
      if (message.service === "/robokudo/beliefs" && message.result) {
        beliefs.clear();
        for (const belief of message.values.objects) beliefs.set(belief.id, belief);
        showBeliefs();
      }
      break;
    case "status":
      if (message.level === "error") view.details.textContent = `server: ${message.msg}`;
      break;
    default:
      break;
  }
}

function published(topic, msg) {
  if (topic === "/robokudo/tree_status") showTree(msg);
  else if (topic === "/robokudo/beliefs") beliefChanges(msg);
  else if (topic === "/robokudo/image") showColor(msg);
  else if (topic === "/robokudo/depth") view.depthImage.src = `data:image/${msg.format};base64,${msg.data}`;
}

// ---------------------------------------------------------------------------------------------- the tree

function shapeOf(node) {
  return `${node.name}(${(node.children || []).map(shapeOf).join(",")})`;
}

function describe(node) {
  const lines = [`${node.name}: ${node.status}`];
  if (node.reason) lines.push(`why: ${node.reason}`);
  if (node.message) lines.push(`message: ${node.message}`);
  if (node.timing) lines.push(`timing: ${timingText(node.timing)}`);
  return lines.join("\n");
}

function timingText(timing) {
  return Object.entries(timing)
    .map(([key, value]) => `${key} ${typeof value === "number" ? Math.round(value * 100) / 100 : value}`)
    .join(", ");
}

function nodeElement(node, path) {
  const item = document.createElement("li");
  const label = document.createElement("span");
  label.className = `node status-${node.status}`;
  label.dataset.path = path;
  label.dataset.name = node.name;
  label.dataset.status = node.status;
  label.textContent = node.name;
  label.title = describe(node);
  label.onclick = () => { view.details.textContent = label.title; };
  item.appendChild(label);
  if (node.children && node.children.length) {
    const list = document.createElement("ul");
    node.children.forEach((child, index) => list.appendChild(nodeElement(child, `${path}/${index}`)));
    item.appendChild(list);
  }
  return item;
}

function drawTree(container, root) {
  const list = document.createElement("ul");
  list.appendChild(nodeElement(root, "0"));
  container.replaceChildren(list);
}

function updateStatuses(container, root) {
  const byPath = new Map();
  (function walk(node, path) {
    byPath.set(path, node);
    (node.children || []).forEach((child, index) => walk(child, `${path}/${index}`));
  })(root, "0");
  for (const label of container.querySelectorAll(".node")) {
    const node = byPath.get(label.dataset.path);
    if (!node) continue;
    label.className = `node status-${node.status}`;
    label.dataset.status = node.status;
    label.title = describe(node);
  }
}

function taskOf(root) {
  const slot = (root.children || []).find((child) => child.name === "task");
  return slot && slot.children && slot.children.length ? slot.children[0] : null;
}

function showTree(msg) {
  view.tick.textContent = `tick ${msg.tick}`;
  const shape = shapeOf(msg.tree);
  if (shape !== shownShape) {
    drawTree(view.tree, msg.tree);
    shownShape = shape;
  } else {
    updateStatuses(view.tree, msg.tree);
  }
  const task = taskOf(msg.tree);
  if (task && task.name !== "idle") {  // keep the last task's statuses after it leaves the slot
    const taskShape = shapeOf(task);
    if (taskShape !== lastTaskShape) {
      drawTree(view.lastTask, task);
      lastTaskShape = taskShape;
    } else {
      updateStatuses(view.lastTask, task);
    }
  }
}

// ---------------------------------------------------------------------------------------------- the camera

const SVG = "http://www.w3.org/2000/svg";

function showColor(msg) {
  view.colorImage.src = `data:image/${msg.format};base64,${msg.data}`;
  view.frameKind.textContent = msg.kind === "analysed" ? "(frame analysed by the task)" : "(live)";
  view.colorFrame.dataset.kind = msg.kind || "live";
  view.colorFrame.dataset.hypotheses = String((msg.hypotheses || []).length);
  view.boxes.setAttribute("viewBox", `0 0 ${msg.width} ${msg.height}`);
  view.boxes.setAttribute("preserveAspectRatio", "none");
  const shapes = [];
  for (const box of msg.hypotheses || []) {
    const [x0, y0, x1, y1] = box.roi;
    const rect = document.createElementNS(SVG, "rect");
    rect.setAttribute("x", x0);
    rect.setAttribute("y", y0);
    rect.setAttribute("width", x1 - x0);
    rect.setAttribute("height", y1 - y0);
    const text = document.createElementNS(SVG, "text");
    text.setAttribute("x", x0 + 3);
    text.setAttribute("y", Math.max(y0 - 4, 12));
    text.textContent = box.label;
    shapes.push(rect, text);
  }
  view.boxes.replaceChildren(...shapes);
}

// ---------------------------------------------------------------------------------------------- beliefs

function beliefChanges(msg) {
  for (const belief of msg.changed || []) beliefs.set(belief.id, belief);
  for (const id of msg.gone || []) {
    const belief = beliefs.get(id);
    if (belief) belief.status = "gone";
  }
  showBeliefs();
}

function attributesText(attributes) {
  return Object.entries(attributes || {})
    .map(([name, a]) => `${name}: ${a.value} (${Math.round(a.confidence * 100)}%)`)
    .join(", ");
}

function showBeliefs() {
  const rows = [...beliefs.values()].sort((a, b) => a.id - b.id).map((belief) => {
    const row = document.createElement("tr");
    row.dataset.id = String(belief.id);
    row.dataset.class = belief.class.label;
    if (belief.status === "gone") row.className = "gone";
    const position = belief.pose.position.map((v) => v.toFixed(2)).join(", ");
    const seen = belief.last_seen ? new Date(belief.last_seen * 1000).toLocaleTimeString() : "";
    for (const text of [belief.id, belief.class.label, belief.region || "", `(${position}) ${belief.pose.frame}`,
      attributesText(belief.attributes), seen]) {
      const cell = document.createElement("td");
      cell.textContent = String(text);
      row.appendChild(cell);
    }
    return row;
  });
  view.beliefs.replaceChildren(...rows);
}

// ---------------------------------------------------------------------------------------------- goals

function goalRow(id) {
  let goal = goals.get(id);
  if (!goal) {
    const row = document.createElement("tr");
    row.dataset.goal = id;
    const cells = [0, 1, 2, 3].map(() => row.appendChild(document.createElement("td")));
    goal = { row, cells };
    goals.set(id, goal);
    view.goals.prepend(row);
  }
  return goal;
}

function sendGoal(text) {
  const id = nextId("goal");
  const goal = goalRow(id);
  goal.cells[0].textContent = id.split("-").pop();
  goal.cells[1].textContent = text;
  goal.cells[2].textContent = "sent";
  const cancel = document.createElement("button");
  cancel.textContent = "cancel";
  cancel.className = "cancel";
  cancel.onclick = () => send({ op: "cancel_action_goal", id, action: ACTION });
  goal.cells[3].replaceChildren(cancel);
  if (!send({ op: "send_action_goal", id, action: ACTION, action_type: ACTION_TYPE, args: { query: text },
    feedback: true })) {
    goal.cells[2].textContent = "not sent: disconnected";
  }
}

function goalFeedback(id, values) {
  const goal = goals.get(id);
  if (!goal) return;
  const running = values.running && values.running.length ? `: ${values.running.join(", ")}` : "";
  goal.cells[2].textContent = `${values.phase}${running}`;
}

function goalResult(id, status, values, accepted) {
  const goal = goals.get(id);
  if (!goal) return;
  const name = accepted === false ? "REFUSED" : GOAL_STATUS[status] || String(status);
  goal.row.className = `goal-${name}`;
  goal.row.dataset.status = name;
  const detail = name === "SUCCEEDED" ? `${values.objects.length} object(s)` : values.reason || values.error || "";
  goal.cells[2].textContent = `${name} ${detail}`;
  goal.cells[3].replaceChildren();
}

view.form.addEventListener("submit", (event) => {
  event.preventDefault();
  const text = view.query.value.trim();
  if (text) sendGoal(text);
});

connect();
