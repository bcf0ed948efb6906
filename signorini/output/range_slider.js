function render({ model, el }) {
  const label = document.createElement("label");
  const input = document.createElement("input");
  const shown = document.createElement("output");
  input.type = "range";
  input.name = model.get("name");
  input.min = model.get("start");
  input.max = model.get("stop");
  input.step = model.get("step");
  input.value = model.get("value");
  input.style.width = "14em";
  shown.textContent = model.get("value");
  label.textContent = model.get("label") + " ";
  input.addEventListener("input", () => { shown.textContent = input.value; });
  input.addEventListener("change", () => {
    model.set("value", Number(input.value));
    model.save_changes();
  });
  label.append(input, " ", shown);
  el.appendChild(label);
}
export default { render };
