// Runs trees in BehaviorTree.CPP with scripted leaves and prints what each tick did to every node, as
// tests/trees/btcpp_harness.py compares it (Run: roots, ticks, halts, error_at, error, blackboard, unreadable).
//
// Input (JSON, argv[1]): [{"name", "xml", "scripts": {"A": ["SUCCESS", ...]}, "ticks", "between" (seconds),
// "blackboard": {"key": int | double | "text"}}]. Output (JSON, argv[2]): {"name": Run, ...}.
// A leaf type whose script holds RUNNING is a StatefulActionNode (halts recorded), else a condition; leaves of one
// type answer from one counter, cycling, as the harness's behaviortreepy leaves do. Observations come from a
// StatusChangeLogger (transitions, to IDLE included), in the harness's _observe rules; nodes are numbered in
// document order (the recursive visitor's pre-order, SubTrees expanded).
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>

#include "behaviortree_cpp/bt_factory.h"
#include "behaviortree_cpp/contrib/json.hpp"
#include "behaviortree_cpp/loggers/abstract_logger.h"

using nlohmann::json;

namespace
{
const char* Name(BT::NodeStatus status)
{
  switch(status)
  {
    case BT::NodeStatus::IDLE: return "IDLE";
    case BT::NodeStatus::RUNNING: return "RUNNING";
    case BT::NodeStatus::SUCCESS: return "SUCCESS";
    case BT::NodeStatus::FAILURE: return "FAILURE";
    case BT::NodeStatus::SKIPPED: return "SKIPPED";
  }
  return "?";
}

struct Transitions : public BT::StatusChangeLogger
{
  explicit Transitions(BT::TreeNode* root) : BT::StatusChangeLogger(root)
  {
    enableTransitionToIdle(true);
  }
  ~Transitions() override
  {
    unsubscribeFromTreeChanges();
  }
  void callback(BT::Duration, const BT::TreeNode& node, BT::NodeStatus, BT::NodeStatus status) override
  {
    std::scoped_lock lock(mutex);
    seen.emplace_back(&node, status);
  }
  void flush() override {}
  std::vector<std::pair<const BT::TreeNode*, BT::NodeStatus>> take()
  {
    std::scoped_lock lock(mutex);
    auto out = std::move(seen);
    seen.clear();
    return out;
  }
  std::mutex mutex;
  std::vector<std::pair<const BT::TreeNode*, BT::NodeStatus>> seen;
};

struct Shared
{
  std::map<std::string, std::vector<std::string>> scripts;
  std::map<std::string, size_t> counters;
  std::vector<std::string> halts;
  std::mutex mutex;
  BT::NodeStatus answer(const std::string& kind)
  {
    std::scoped_lock lock(mutex);
    const auto& script = scripts.at(kind);
    const auto& text = script[counters[kind]++ % script.size()];
    return BT::convertFromString<BT::NodeStatus>(text);
  }
};

class ScriptedAction : public BT::StatefulActionNode
{
public:
  ScriptedAction(const std::string& name, const BT::NodeConfig& config, Shared* shared, std::string kind)
    : BT::StatefulActionNode(name, config), shared_(shared), kind_(std::move(kind))
  {}
  BT::NodeStatus onStart() override { return shared_->answer(kind_); }
  BT::NodeStatus onRunning() override { return shared_->answer(kind_); }
  void onHalted() override
  {
    std::scoped_lock lock(shared_->mutex);
    shared_->halts.push_back(kind_);
  }

private:
  Shared* shared_;
  std::string kind_;
};

json RunCase(const json& spec)
{
  json run = { { "roots", json::array() }, { "ticks", json::array() }, { "halts", json::array() },
               { "error_at", nullptr }, { "error", "" }, { "blackboard", json::object() },
               { "unreadable", json::array() } };
  Shared shared;
  BT::BehaviorTreeFactory factory;
  for(const auto& [kind, script] : spec["scripts"].items())
  {
    shared.scripts[kind] = script.get<std::vector<std::string>>();
    const bool running = std::find(shared.scripts[kind].begin(), shared.scripts[kind].end(), "RUNNING") !=
                         shared.scripts[kind].end();
    const std::string id = kind;
    if(running)
    {
      factory.registerBuilder(BT::CreateManifest<ScriptedAction>(id, {}),
                              [&shared, id](const std::string& name, const BT::NodeConfig& config) {
                                return std::make_unique<ScriptedAction>(name, config, &shared, id);
                              });
    }
    else
    {
      factory.registerSimpleCondition(id, [&shared, id](BT::TreeNode&) { return shared.answer(id); });
    }
  }
  auto board = BT::Blackboard::create();
  const json initial = spec.value("blackboard", json::object());
  for(const auto& [key, value] : initial.items())
  {
    if(value.is_number_integer())
      board->set<int>(key, value.get<int>());
    else if(value.is_number())
      board->set<double>(key, value.get<double>());
    else
      board->set<std::string>(key, value.get<std::string>());
  }
  BT::Tree tree;
  try
  {
    tree = factory.createTreeFromText(spec["xml"].get<std::string>(), board);
  }
  catch(const std::exception& error)
  {
    run["error_at"] = -1;
    run["error"] = error.what();
    return run;
  }
  std::vector<const BT::TreeNode*> nodes;
  BT::applyRecursiveVisitor(tree.rootNode(), [&](BT::TreeNode* node) { nodes.push_back(node); });
  std::map<const BT::TreeNode*, std::string> state;
  for(auto* node : nodes)
    state[node] = "IDLE";
  Transitions transitions(tree.rootNode());
  const int ticks = spec["ticks"].get<int>();
  const double between = spec.value("between", 0.0);
  auto paced = std::chrono::steady_clock::now();
  size_t before = 0;
  for(int tick = 0; tick < ticks; tick++)
  {
    BT::NodeStatus root;
    try
    {
      root = tree.tickExactlyOnce();
    }
    catch(const std::exception& error)
    {
      run["error_at"] = tick;
      run["error"] = error.what();
      break;
    }
    run["roots"].push_back(Name(root));
    std::map<const BT::TreeNode*, std::vector<std::string>> by_node;
    for(const auto& [node, status] : transitions.take())
      by_node[node].push_back(Name(status));
    json row = json::array();
    for(auto* node : nodes)
    {  // the harness's _observe: what the tick did to the node, from the statuses it was set to
      std::string status = state[node];
      std::string seen = status == "RUNNING" ? "RUNNING" : "-";
      for(const auto& next : by_node[node])
      {
        if(next == status)
          continue;
        if(next != "IDLE")
          seen = next;
        else if(status == "RUNNING")
          seen = "HALTED";
        status = next;
      }
      state[node] = status;
      row.push_back(seen);
    }
    run["ticks"].push_back(row);
    {
      std::scoped_lock lock(shared.mutex);
      std::vector<std::string> halted(shared.halts.begin() + before, shared.halts.end());
      std::sort(halted.begin(), halted.end());
      before = shared.halts.size();
      run["halts"].push_back(halted);
    }
    if(between > 0)
    {
      paced += std::chrono::microseconds(static_cast<int64_t>(between * 1e6));
      std::this_thread::sleep_until(paced);
    }
  }
  auto root_board = tree.rootBlackboard();
  for(const auto& key : root_board->getKeys())
  {
    const std::string name(key);
    auto any = root_board->getAnyLocked(name);
    try
    {
      if(!any || any->empty())
        throw std::runtime_error("empty");
      run["blackboard"][name] = any->cast<std::string>();
    }
    catch(const std::exception&)
    {
      run["unreadable"].push_back(name);
    }
  }
  return run;
}
}  // namespace

int main(int argc, char** argv)
{
  if(argc != 3)
  {
    std::cerr << "usage: trace_driver cases.json traces.json\n";
    return 2;
  }
  std::ifstream input(argv[1]);
  const json cases = json::parse(input);
  json out = json::object();
  for(const auto& spec : cases)
  {
    out[spec["name"].get<std::string>()] = RunCase(spec);
  }
  std::ofstream output(argv[2]);  // not stdout: BT.CPP prints some warnings there
  output << out.dump(1, ' ', false, json::error_handler_t::replace) << "\n";
  return 0;
}
