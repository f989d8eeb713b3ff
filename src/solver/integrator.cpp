#include "railcrash/solver/integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace railcrash {

void PhaseClock::start() {
  on_ = true;
  current_ = Phase::Other;
  seconds_.fill(0.0);
  since_ = std::chrono::steady_clock::now();
}

Phase PhaseClock::enter(Phase phase) {
  const auto now = std::chrono::steady_clock::now();
  seconds_[static_cast<std::size_t>(current_)] += std::chrono::duration<double>(now - since_).count();
  since_ = now;
  const Phase left = current_;
  current_ = phase;
  return left;
}

const std::array<double, kPhaseCount>& PhaseClock::stop() {
  if (on_) enter(current_);
  on_ = false;
  return seconds_;
}

void Integrator::report_events(const std::vector<EventRecord>& events, const double* y, int element) {
  for (const EventRecord& record : events) {
    observer_->event(record, y);
    if (chatter_.record(record)) throw SolverError(chatter_message(record));
  }
  if (!events.empty()) deliver_step(events.front().t, y, element);
  outcome_.events.insert(outcome_.events.end(), events.begin(), events.end());
  outcome_.stats.events += static_cast<long>(events.size());
}

std::string Integrator::chatter_message(const EventRecord& last) const {
  std::string where, type;
  for (const auto& e : system_.model().elements())
    if (e->name() == last.element) where = e->where().prefix(), type = " (" + e->type() + ")";
  std::ostringstream text;
  text << where << "element '" << last.element << "'" << type << " changed mode " << chatter_.count()
       << " times in a row at one instant (t = " << chatter_.first_time() << " s, all within "
       << last.t - chatter_.first_time() << " s; the last: \"" << last.what << "\"): it chatters on the boundary between two of its modes and the run would not end. The results "
       << "up to here are kept. Another --rtol or --integrator euler may pass it; please report the model: a law that "
       << "chatters is railcrash's defect, not the model's";
  return text.str();
}

void Integrator::observe_before_event(double t, const double* y, int element) {
  if (observe_steps_ && non_finite_entry(y).empty()) deliver_step(t, y, element);
}

void Integrator::deliver_step(double t, const double* y, int element) {
  if (!observe_steps_) return;
  const PhaseClock::Scope timed(phase_clock(), Phase::Output);
  const double* lambda = y + 2 * system_.body_unknowns();
  FreshOutputs step_fresh;  // the outputs every step evaluates: those of the elements the observer reads
  step_fresh.marked = step_columns_.empty() ? nullptr : step_columns_.data();
  const double* ready = element < 0 && y == current_state() ? current_outputs() : nullptr;
  if (ready) {
    observer_->step(t, y, lambda, ready, step_fresh);
    return;
  }
  // At a located event only the changed element's outputs are evaluated again: evaluating all
  // of them at every event made a train's cost grow as N^2 (events grow with N; 100 + 100
  // cars over 0.01 s: 5.0 s before the per-event evaluation, 7.8 s with it, CPU).
  // The other outputs in step_outputs_ are from an earlier state: the observers are told which
  // columns are fresh, so that no sum mixes this instant's values with older ones.
  FreshOutputs fresh;
  if (element >= 0) {
    system_.element_outputs(element, y, lambda, step_outputs_.data());
    const auto [begin, end] = system_.output_range(element);
    fresh = FreshOutputs{begin, end};
  } else if (step_elements_.empty()) {
    system_.outputs(y, lambda, step_outputs_.data());
  } else {
    for (std::size_t e = 0; e < step_elements_.size(); ++e)
      if (step_elements_[e] != 0) system_.element_outputs(static_cast<int>(e), y, lambda, step_outputs_.data());
    fresh = step_fresh;
  }
  observer_->step(t, y, lambda, step_outputs_.data(), fresh);
}

void Integrator::choose_step_outputs() {
  step_elements_.clear();
  step_columns_.clear();
  if (!observe_steps_) return;
  const std::size_t element_count = system_.model().elements().size();
  std::vector<char> marked(system_.output_names().size(), char{0});
  observer_->mark_step_columns(marked);
  std::vector<char> elements(element_count, char{0}), columns(marked.size(), char{0});
  bool every_element = true;
  for (std::size_t e = 0; e < element_count; ++e) {
    const auto [begin, end] = system_.output_range(static_cast<int>(e));
    elements[e] = std::any_of(marked.begin() + begin, marked.begin() + end, [](char m) { return m != 0; }) ? 1 : 0;
    std::fill(columns.begin() + begin, columns.begin() + end, elements[e]);
    every_element = every_element && (elements[e] != 0 || begin == end);
  }
  if (every_element) return;  // every output per step, as without marks
  step_elements_ = std::move(elements);
  step_columns_ = std::move(columns);
}

std::string Integrator::non_finite_entry(const double* y) const {
  for (int k = 0; k < system_.size(); ++k)
    if (!std::isfinite(y[k])) {
      std::ostringstream text;
      text << system_.unknown_name(k) << " is " << y[k];
      return text.str();
    }
  return "";
}

void Integrator::deliver_sample(double t) {
  const PhaseClock::Scope timed(phase_clock(), Phase::Output);
  state_at(t, sample_y_, sample_quadratures_);
  const std::string bad = non_finite_entry(sample_y_.data());
  if (!bad.empty()) {
    std::ostringstream msg;
    msg << divergence_phrase() << " at t = " << t << ": " << bad << divergence_advice(last_sample_y_, t_sampled_);
    throw StepFailure(msg.str());
  }
  outcome_.most_energy_turned_over =
      std::max(outcome_.most_energy_turned_over,
               system_.work_balance(outcome_.initial_energy, sample_y_.data(), sample_quadratures_.data()).turned_over);
  const int nq = system_.body_unknowns();
  const double* lambda = sample_y_.data() + 2 * nq;
  if (observe_sample_forces_) {  // the outputs and the forces from one sweep over the elements
    DaeSystem::SweepExtras extras;
    extras.outputs = sample_outputs_.data();
    extras.y_lambda = lambda;
    system_.generalized_forces(t, sample_y_.data(), sample_y_.data() + nq, sample_forces_.data(), nullptr, nullptr, lambda,
                               &extras);
    observer_->sample_with_forces(t, sample_y_.data(), lambda, sample_quadratures_.data(), sample_outputs_.data(),
                                  sample_forces_.data());
  } else {
    system_.outputs(sample_y_.data(), lambda, sample_outputs_.data());
    observer_->sample(t, sample_y_.data(), lambda, sample_quadratures_.data(), sample_outputs_.data());
  }
  const std::string observer_failure = observer_->failure();  // a failed write: stop at once
  if (!observer_failure.empty()) {
    std::ostringstream msg;
    // What the files hold is the writer's to say (its failure names the rows on disk): the
    // samples computed are not all there after a failed write.
    msg << observer_failure << "; the run stopped at t = " << t;
    if (last_sample_y_.empty()) msg << " before its first sample";
    throw StepFailure(msg.str());
  }
  last_sample_residual_ = system_.constraint_residual(sample_y_.data(), constraint_scratch_);
  outcome_.max_constraint_residual = std::max(outcome_.max_constraint_residual, last_sample_residual_);
  t_sampled_ = t;
  last_sample_y_ = sample_y_;
  last_sample_quadratures_ = sample_quadratures_;
}

double Integrator::next_output_time() const {
  return std::min(t_end_, static_cast<double>(output_index_) * output_interval_);
}

void Integrator::sample_up_to(double t_limit) {
  for (double t_out = next_output_time(); t_sampled_ < t_end_ && t_out <= t_limit * (1.0 + 1e-14); t_out = next_output_time()) {
    deliver_sample(t_out);
    ++output_index_;
  }
}

void Integrator::take_run_from(Integrator& previous) {
  outcome_ = std::move(previous.outcome_);
  observer_ = previous.observer_;
  t_end_ = previous.t_end_;
  chatter_ = std::move(previous.chatter_);  // the run's guard goes on (its t_end, its limit, its counts)
  chatter_limit_ = previous.chatter_limit_;
  output_interval_ = previous.output_interval_;
  output_index_ = previous.output_index_;
  t_sampled_ = previous.t_sampled_;
  last_sample_residual_ = previous.last_sample_residual_;
  sample_y_ = std::move(previous.sample_y_);
  sample_quadratures_ = std::move(previous.sample_quadratures_);
  sample_outputs_ = std::move(previous.sample_outputs_);
  sample_forces_ = std::move(previous.sample_forces_);
  observe_sample_forces_ = previous.observe_sample_forces_;
  last_sample_y_ = std::move(previous.last_sample_y_);
  last_sample_quadratures_ = std::move(previous.last_sample_quadratures_);
  observe_steps_ = previous.observe_steps_;
  time_phases_ = previous.time_phases_;
  phase_clock_ = previous.phase_clock_;
  previous.phase_clock_ = PhaseClock{};
  step_outputs_ = std::move(previous.step_outputs_);
  step_elements_ = std::move(previous.step_elements_);
  step_columns_ = std::move(previous.step_columns_);
  previous.observer_ = nullptr;
}

RunOutcome Integrator::run(double t_end, double output_interval, RunObserver& observer, const std::atomic<bool>* stop) {
  // (A run spec's 0 means t_end / 500: output_interval_of gives the interval. Sampling every
  // 0 s never reached t_end: a test that passed the spec's 0 hung.)
  RAILCRASH_DEMAND(output_interval > 0.0);
  outcome_ = RunOutcome{};
  if (time_phases_) phase_clock_.start();
  const auto wall_start = std::chrono::steady_clock::now();
  observer_ = &observer;
  observe_steps_ = observer.observes_steps();
  choose_step_outputs();
  step_outputs_.assign(system_.output_names().size(), 0.0);
  sample_outputs_.assign(system_.output_names().size(), 0.0);
  observe_sample_forces_ = observer.wants_sample_forces();
  sample_forces_.assign(observe_sample_forces_ ? static_cast<std::size_t>(system_.body_unknowns()) : 0, 0.0);
  t_end_ = t_end;
  chatter_ = ChatterGuard(t_end, chatter_limit_);
  output_interval_ = output_interval;
  output_index_ = 1;
  t_sampled_ = 0.0;
  last_sample_y_.clear();
  last_sample_quadratures_.clear();
  double t_reached = 0.0;
  // The integrator taking the steps: this one, or the successor it handed the run to.
  Integrator* active = this;
  std::unique_ptr<Integrator> successor;
  bool dense = false;
  // The successor (hand_over, rescue) goes on with the run: this one's counters close first.
  const auto pass_run_to = [&](std::unique_ptr<Integrator> next) {
    active->finish();
    next->take_run_from(*active);
    next->continue_from_hand_over();
    successor = std::move(next);  // (the previous successor, if any, is done with)
    active = successor.get();
    dense = active->dense_output();
  };
  // The successor gives the run back (returns_run): this integrator goes on from its state.
  const auto take_run_back = [&](double t) {
    std::vector<double> y, quadratures;
    active->state_for_successor(t, y, quadratures);
    active->finish();
    take_run_from(*active);
    active = this;
    dense = dense_output();
    resume(t, std::move(y), quadratures);
    successor.reset();
  };
  try {
    {
      const PhaseClock::Scope timed(phase_clock(), Phase::Start);
      start(t_end);
    }
    state_at(0.0, sample_y_, sample_quadratures_);
    outcome_.initial_energy = energy(sample_y_.data(), sample_quadratures_.data());
    outcome_.max_constraint_residual = 0.0;
    deliver_sample(0.0);
    dense = dense_output();
    long steps_taken = 0;  // advance() calls in this run
    while (t_reached < t_end) {
      if (stop && stop->load()) {
        active->outcome_.message = "interrupted at t = " + std::to_string(active->t_sampled_);
        break;
      }
      if (steps_taken++ >= active->max_steps()) {
        std::ostringstream msg;
        msg << "stopped at t = " << t_reached << " after --max-steps " << active->max_steps() << " steps"
            << active->step_limit_advice(t_end);
        active->outcome_.message = msg.str();
        break;
      }
      try {
        t_reached = active->advance(t_end);
      } catch (const StepFailure& failure) {
        double t_good = t_reached;
        std::unique_ptr<Integrator> next = active->rescue(failure.what(), &t_good);
        if (!next) throw;
        pass_run_to(std::move(next));
        t_reached = t_good;
        continue;
      }
      const std::string bad = active->non_finite_entry(active->current_state());
      if (!bad.empty()) {
        std::ostringstream msg;
        msg << active->divergence_phrase() << " at t = " << t_reached << ": " << bad
            << active->divergence_advice(active->last_sample_y_, active->t_sampled_);
        throw StepFailure(msg.str());
      }
      // The end of a step that passes an output time is the sample of an integrator without
      // dense output.
      const auto sample_here = [&] { return !dense && t_reached >= active->next_output_time() * (1.0 - 1e-12); };
      // A successor's step judged less accurate than the run allows is neither delivered nor
      // sampled: the first integrator takes the run back from its end (its joints closed) and
      // the step's end is delivered from there.
      if (active != this && active->returns_run(t_reached, active->current_state(), sample_here()))
        take_run_back(t_reached);
      active->deliver_step(t_reached, active->current_state());
      if (dense) {
        active->sample_up_to(t_reached);
      } else if (sample_here()) {
        active->deliver_sample(t_reached);
        while (static_cast<double>(active->output_index_) * active->output_interval_ <= t_reached * (1.0 + 1e-12))
          ++active->output_index_;
      }
      if (t_reached < t_end)
        if (std::unique_ptr<Integrator> next = active->hand_over(t_reached, active->current_state()))
          pass_run_to(std::move(next));
    }
  } catch (const InputError&) {
    active->finish();
    active->phase_clock_.stop();
    throw;
  } catch (const std::exception& e) {
    active->outcome_.message = e.what();
  }
  RunOutcome& outcome = active->outcome_;
  outcome.ok = outcome.message.empty() && t_reached >= t_end;  // a run that did not reach t_end is never ok
  if (outcome.ok) {
    outcome.t_reached = t_reached;
    active->final_state(outcome.y, outcome.quadratures);
  } else {  // a failed or interrupted run ends at its last output sample, the last good state
    outcome.t_reached = active->t_sampled_;
    outcome.y = active->last_sample_y_;
    outcome.quadratures = active->last_sample_quadratures_;
  }
  if (!outcome.y.empty()) outcome.final_energy = active->energy(outcome.y.data(), outcome.quadratures.data());
  else outcome.final_energy = outcome.initial_energy;  // stopped before the first sample, at t = 0
  active->finish();
  outcome.stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (active->phase_clock_.on()) {
    outcome.stats.phase_seconds = active->phase_clock_.stop();
    outcome.stats.phases_timed = true;
  }
  active->observer_ = nullptr;
  return std::move(outcome);
}

double max_abs(const std::vector<double>& values) {
  double worst = 0.0;
  for (double v : values) worst = std::max(worst, std::abs(v));
  return worst;
}

}  // namespace railcrash
